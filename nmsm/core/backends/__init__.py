"""Back ends: the solvers a problem is handed to, registered by name.

``problem.solve(name, **options)`` finds the back end registered as ``name``
(:func:`~nmsm.core.backends.base.get_backend`) and returns its
:class:`~nmsm.core.solution.Solution`. nmsm's own, registered in ``builtin.py``:

* ``ipopt`` (:mod:`~nmsm.core.backends.ipopt`);
* ``least_squares`` (:mod:`~nmsm.core.backends.least_squares`);
* ``levenberg_marquardt`` (:mod:`~nmsm.core.backends.levenberg_marquardt`), which also
  solves a :class:`~nmsm.core.residual_problem.ResidualProblem`;
* ``lifted_least_squares`` (:mod:`~nmsm.core.backends.lifted_least_squares`), for a problem
  with lifted parameters.

A plugin adds its own through the ``nmsm_backends`` hook (docs/plugins.md).
"""

from __future__ import annotations

from nmsm.core.backends.base import Backend, backend_names, get_backend

__all__ = ["Backend", "backend_names", "get_backend"]

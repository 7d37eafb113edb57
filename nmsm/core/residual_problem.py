"""The least-squares problem contract: ``min sum(r(x)**2)`` subject to ``lower <= x <= upper``,
stated by its residuals and their exact Jacobian.

For problems whose Jacobian has a structure a back end can exploit and an
:class:`~nmsm.core.problem.OptimizationProblem` does not state (Joint Model
Personalization's block-arrow Jacobian: each frame's residuals depend on that frame's
coordinates and on the shared model parameters). The problem evaluates ``r`` and ``J``
itself, as one of :mod:`nmsm.core.jacobians`; a back end that takes it
(``levenberg_marquardt``) is given the start ``x`` as ``initial_guess``, since such a
problem is often solved again from other starts.
"""

from __future__ import annotations

import abc

import numpy as np

from nmsm.core.jacobians import Jacobian


class ResidualProblem(abc.ABC):
    """Residuals ``r(x)`` (m,) of variables ``x`` (n,) in a box; see the module docstring.

    :meth:`values` and :meth:`costs` say what a :class:`~nmsm.core.solution.Solution` reports
    at ``x``: named blocks of variables (default: ``{"x": x}``) and each term's contribution to
    ``sum(r**2)`` (default: one entry, :attr:`name`).
    """

    name: str = "residuals"

    @abc.abstractmethod
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lower, upper)``, each (n,); infinite where a variable is unbounded."""

    @abc.abstractmethod
    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, Jacobian]:
        """Residuals (m,) and their Jacobian (m x n) at ``x`` (n,)."""

    def values(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """The solution's values at ``x``, by name."""
        return {"x": np.asarray(x, dtype=float)}

    def costs(self, x: np.ndarray) -> dict[str, float]:
        """Each term's ``sum(r_term**2)`` at ``x``."""
        r, _ = self.evaluate(x)
        return {self.name: float(r @ r)}

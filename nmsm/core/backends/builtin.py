"""nmsm's own back ends, registered through the ``nmsm_backends`` hook (entry point
``builtin_backends``), as a plugin registers its own."""

from __future__ import annotations

from nmsm.core.backends.ipopt import IpoptBackend
from nmsm.core.backends.least_squares import LeastSquaresBackend
from nmsm.core.backends.lifted_least_squares import LiftedLeastSquaresBackend
from nmsm.core.backends.levenberg_marquardt import LevenbergMarquardtBackend
from nmsm.hookspecs import hookimpl


@hookimpl
def nmsm_backends() -> list[type]:
    return [IpoptBackend, LeastSquaresBackend, LevenbergMarquardtBackend, LiftedLeastSquaresBackend]

"""nmsm's own back ends, registered through the ``nmsm_backends`` hook (entry point
``builtin_backends``), as a plugin registers its own."""

from __future__ import annotations

from nmsm.core.backends.ipopt import IpoptBackend
from nmsm.core.backends.least_squares import LeastSquaresBackend
from nmsm.hookspecs import hookimpl


@hookimpl
def nmsm_backends() -> list[type]:
    return [IpoptBackend, LeastSquaresBackend]

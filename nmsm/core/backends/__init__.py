"""Back ends that solve an :class:`~nmsm.core.problem.OptimizationProblem`."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

BACKENDS = ("least_squares", "ipopt")


def get_backend(name: str) -> Callable[..., Any]:
    """The solve function of back end ``name``."""
    if name == "least_squares":
        from nmsm.core.backends.least_squares import solve_least_squares

        return solve_least_squares
    if name == "ipopt":
        from nmsm.core.backends.ipopt import solve_ipopt

        return solve_ipopt
    raise ValueError(f"unknown back end '{name}' (expected one of {', '.join(BACKENDS)})")

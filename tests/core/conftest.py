"""Small known-answer problems shared by the core tests."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from nmsm.core.problem import OptimizationProblem


def _rosenbrock(name: str = "rosen") -> OptimizationProblem:
    """Rosenbrock as two residuals, bounded; minimum 0 at (1, 1), start (-1.2, 1)."""
    problem = OptimizationProblem(name)
    x = problem.variable("x", [-1.2, 1.0], lower=-5, upper=5)
    problem.add_cost("a", 1 - x[0])
    problem.add_cost("b", 10 * (x[1] - x[0] ** 2))
    return problem


@pytest.fixture
def rosenbrock() -> Callable[..., OptimizationProblem]:
    """Factory of the Rosenbrock problem (``rosenbrock(name)``)."""
    return _rosenbrock

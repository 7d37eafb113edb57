"""The back end ``lifted_least_squares``: a problem whose terms are built on parameters standing
for affine expressions of the variables solves to the same point as the problem written on the
expressions; the other back ends refuse it."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.problem import OptimizationProblem

_A = np.array([[1.0, 2.0, 0.0], [0.0, 1.0, -1.0], [1.0, 0.0, 1.0], [0.5, 0.5, 0.5]])
_TARGET = np.array([1.0, 0.3, -0.4, 0.8])


def _problem(lift: bool) -> OptimizationProblem:
    """Residuals ``sin(z) - target`` and ``0.1 x`` with ``z = A x + 0.2`` (4,), ``x`` (3,) in a box."""
    problem = OptimizationProblem("lifted" if lift else "direct")
    x = problem.variable("x", [0.1, 0.2, 0.3], lower=-2.0, upper=[2.0, 2.0, 0.25])
    z_of_x = cs.DM(_A) @ x + 0.2
    z = problem.lifted_parameter("z", z_of_x, _A @ [0.1, 0.2, 0.3] + 0.2) if lift else z_of_x
    problem.add_cost("fit", cs.sin(z) - cs.DM(_TARGET))
    problem.add_cost("small", 0.1 * x)
    return problem


def test_lifted_problem_solves_to_the_direct_problems_point() -> None:
    direct = _problem(lift=False).solve("least_squares", ftol=1e-14, xtol=1e-14, gtol=1e-14)
    lifted_problem = _problem(lift=True)
    lifted = lifted_problem.solve("lifted_least_squares", ftol=1e-14, xtol=1e-14, gtol=1e-14)
    assert lifted.backend == "lifted_least_squares" and lifted.success and direct.success
    np.testing.assert_allclose(lifted["x"], direct["x"], atol=1e-9)
    assert lifted.cost == pytest.approx(direct.cost, rel=1e-9)
    assert lifted.term_costs == pytest.approx(direct.term_costs, rel=1e-6)
    # the lifted parameter holds its expression's value at the solution
    np.testing.assert_allclose(lifted_problem.parameters["z"].value.ravel(), _A @ lifted["x"].ravel() + 0.2,
                               atol=1e-12)


@pytest.mark.parametrize("backend", ["least_squares", "ipopt", "levenberg_marquardt"])
def test_other_backends_refuse_lifted_parameters(backend: str) -> None:
    with pytest.raises(ValueError, match="has lifted parameters \\(z\\), which the .* back end cannot follow"):
        _problem(lift=True).solve(backend)


def test_lifted_parameter_shape_must_match_its_value() -> None:
    problem = OptimizationProblem()
    x = problem.variable("x", [0.0, 0.0])
    with pytest.raises(ValueError, match="lifted parameter 'z': expression of shape \\(2, 1\\), value of shape"):
        problem.lifted_parameter("z", 2 * x, [0.0, 0.0, 0.0])
    assert "z" not in problem.parameters and not problem.lifted

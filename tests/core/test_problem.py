"""OptimizationProblem and both back ends on problems with known answers."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.problem import OptimizationProblem


@pytest.mark.parametrize("backend", ["least_squares", "ipopt", "levenberg_marquardt"])
def test_rosenbrock_minimum(rosenbrock, backend: str) -> None:
    sol = rosenbrock().solve(backend, **({"print_level": 0} if backend == "ipopt" else {}))
    assert sol.success
    np.testing.assert_allclose(sol["x"].ravel(), [1.0, 1.0], atol=1e-6)
    assert sol.cost < 1e-12


def test_scaling_is_invisible_to_terms() -> None:
    prob = OptimizationProblem()
    x = prob.variable("x", 0.5, lower=0.0, upper=1000.0)  # scaled by its bound range
    prob.add_cost("fit", (x - 123.0) / 10.0)
    sol = prob.solve("least_squares")
    assert abs(sol["x"].item() - 123.0) < 1e-6


def test_bounds_active_and_parameters() -> None:
    prob = OptimizationProblem()
    x = prob.variable("x", np.zeros(3), lower=-1, upper=[1, 1, 0.25])
    target = prob.parameter("target", [0.5, -2.0, 3.0])
    prob.add_cost("fit", x - target)
    sol = prob.solve("ipopt", print_level=0)
    np.testing.assert_allclose(sol["x"].ravel(), [0.5, -1.0, 0.25], atol=1e-6)
    prob.set_parameter("target", [0.1, 0.2, 0.2])
    sol = prob.solve("least_squares")
    np.testing.assert_allclose(sol["x"].ravel(), [0.1, 0.2, 0.2], atol=1e-6)


def test_constraint_report_names_active_block() -> None:
    prob = OptimizationProblem()
    x = prob.variable("x", [0.0, 0.0])
    prob.add_cost("pull", x - cs.DM([2.0, 2.0]))
    prob.add_constraint("sum_le_1", x[0] + x[1], -np.inf, 1.0)
    sol = prob.solve("ipopt", print_level=0)
    np.testing.assert_allclose(sol["x"].ravel(), [0.5, 0.5], atol=1e-6)
    (status,) = sol.constraints
    assert status.name == "sum_le_1" and status.n_active == 1 and status.max_violation < 1e-8
    assert "sum_le_1" in sol.summary() or "1 with active bounds" in sol.summary()


def test_least_squares_rejects_constraints() -> None:
    prob = OptimizationProblem()
    x = prob.variable("x", [0.0])
    prob.add_cost("c", x)
    prob.add_constraint("g", x, 1, 2)
    with pytest.raises(ValueError, match="least-squares back end handles bounds only"):
        prob.solve("least_squares")
    with pytest.raises(ValueError, match="levenberg_marquardt back end handles bounds only"):
        prob.solve("levenberg_marquardt")


def test_matrix_variable_column_major_roundtrip() -> None:
    prob = OptimizationProblem()
    init = np.arange(6.0).reshape(2, 3)
    w = prob.variable("w", init)
    prob.add_cost("fit", cs.vec(w) - cs.vec(cs.DM(init * 2)))
    sol = prob.solve("least_squares")
    np.testing.assert_allclose(sol["w"], init * 2, atol=1e-8)


def test_unknown_backend_lists_the_registered_ones(rosenbrock) -> None:
    from nmsm.errors import RegistryError

    with pytest.raises(RegistryError, match=r"unknown back end 'simplex'; registered back ends: .*ipopt.*least_squares"):
        rosenbrock().solve("simplex")
    with pytest.raises(RegistryError, match="did you mean 'ipopt'"):
        rosenbrock().solve("ipot")

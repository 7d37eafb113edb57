"""The IPOPT back end's choice of AD mode for the constraint Jacobian
(nmsm.core.backends.ipopt.jacobian_direction_options)."""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.core.backends.ipopt import jacobian_direction_options
from nmsm.core.problem import OptimizationProblem


def _problem(n_inputs: int, n_rows: int) -> OptimizationProblem:
    """``n_rows`` constraints, each a function of all ``n_inputs`` variables of its block."""
    problem = OptimizationProblem("directions")
    v = problem.variable("v", np.ones((n_inputs * 3,)))
    problem.add_cost("size", v)
    for block in range(3):
        x = v[block * n_inputs:(block + 1) * n_inputs]
        rows = cs.vertcat(*[cs.sum1(cs.sin(x * (k + 1))) for k in range(n_rows)])
        problem.add_constraint(f"block_{block}", rows, -1.0, 1.0)
    return problem


def test_many_inputs_few_outputs_take_reverse_mode() -> None:
    assert jacobian_direction_options(_problem(40, 3)) == {"oracle_options": {"ad_weight": 1.0}}


def test_few_inputs_many_outputs_take_forward_mode() -> None:
    assert jacobian_direction_options(_problem(3, 40)) == {"oracle_options": {"ad_weight": 0.0}}


def test_the_chosen_mode_gives_the_same_solution() -> None:
    problem = _problem(6, 2)
    default = problem.solve("ipopt", print_level=0)
    chosen = problem.solve("ipopt", print_level=0, casadi_options=jacobian_direction_options(problem))
    assert default.success and chosen.success
    np.testing.assert_allclose(chosen.x_scaled, default.x_scaled, rtol=1e-8, atol=1e-10)


def test_no_constraints_no_option() -> None:
    problem = OptimizationProblem("free")
    v = problem.variable("v", np.ones(2))
    problem.add_cost("size", v)
    assert jacobian_direction_options(problem) == {}


def _mixed() -> OptimizationProblem:
    """Per-point blocks (many inputs, one row each: reverse) and a block whose every row
    shares a global variable ``w`` with few inputs a row (forward)."""
    problem = OptimizationProblem("mixed")
    v = problem.variable("v", np.linspace(0.1, 0.9, 40))
    w = problem.variable("w", np.array([0.5]))
    problem.add_cost("size", cs.vertcat(v, w))
    for block in range(4):
        x = v[block * 10:(block + 1) * 10]
        problem.add_constraint(f"point_{block}", cs.sum1(cs.sin(x) * x), -5.0, 5.0)
    problem.add_constraint("lifted", v * w - cs.cos(v), -5.0, 5.0)
    return problem


def test_blocks_take_their_own_mode_and_the_jacobian_is_unchanged() -> None:
    problem = _mixed()
    options = jacobian_direction_options(problem)
    assert set(options) == {"jac_g"}
    g, _, _ = problem.constraint_vector()
    x = problem.scaled_vector()
    expected = cs.Function("j", [x, problem.parameter_vector()], [g, cs.jacobian(g, x)])
    point = np.random.default_rng(3).normal(size=x.numel())
    got = options["jac_g"](point, problem.parameter_values())
    want = expected(point, problem.parameter_values())
    np.testing.assert_array_equal(np.asarray(got[0]), np.asarray(want[0]))
    np.testing.assert_allclose(np.asarray(cs.densify(got[1])), np.asarray(cs.densify(want[1])), rtol=1e-14,
                               atol=1e-14)
    default = problem.solve("ipopt", print_level=0)
    chosen = problem.solve("ipopt", print_level=0, casadi_options=options)
    assert default.success and chosen.success
    np.testing.assert_allclose(chosen.x_scaled, default.x_scaled, rtol=1e-8, atol=1e-10)

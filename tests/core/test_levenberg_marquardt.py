"""The bound-constrained Levenberg-Marquardt solver and its three linear-algebra back ends."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize
import scipy.sparse

from nmsm.core.backends import get_backend
from nmsm.core.backends.levenberg_marquardt import Tolerances, solve
from nmsm.core.jacobians import BlockArrowJacobian, DenseJacobian, SparseJacobian
from nmsm.core.residual_problem import ResidualProblem


def _block_to_dense(jac: BlockArrowJacobian) -> np.ndarray:
    f, m, n, k = jac.shape
    dense = np.zeros((f * m, f * n + k))
    for i in range(f):
        dense[i * m:(i + 1) * m, i * n:(i + 1) * n] = jac.dq[i]
        dense[i * m:(i + 1) * m, f * n:] = jac.dp[i]
    return dense


def test_block_arrow_step_equals_dense_step_with_fixed_variables():
    rng = np.random.default_rng(0)
    f, m, n, k = 7, 9, 3, 4
    block = BlockArrowJacobian(rng.normal(size=(f, m, n)), rng.normal(size=(f, m, k)))
    dense = DenseJacobian(_block_to_dense(block))
    sparse = SparseJacobian(scipy.sparse.csc_matrix(dense.matrix))
    r = rng.normal(size=f * m)
    g = dense.gradient(r)
    np.testing.assert_allclose(block.gradient(r), g, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(sparse.gradient(r), g, rtol=1e-12, atol=1e-12)
    diag = dense.normal_diagonal()
    np.testing.assert_allclose(block.normal_diagonal(), diag, rtol=1e-12)
    np.testing.assert_allclose(sparse.normal_diagonal(), diag, rtol=1e-12)
    free = np.ones(f * n + k, dtype=bool)
    free[[1, 5, f * n + 2]] = False  # a coordinate of two frames and one parameter held
    expected = dense.damped_step(g, free, 0.3, diag)
    assert np.all(expected[~free] == 0)
    np.testing.assert_allclose(block.damped_step(g, free, 0.3, diag), expected, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sparse.damped_step(g, free, 0.3, diag), expected, rtol=1e-9, atol=1e-12)
    s = rng.normal(size=f * n + k)
    assert block.squared_norm_of_product(s) == pytest.approx(dense.squared_norm_of_product(s), rel=1e-12)


def _rosenbrock(x: np.ndarray) -> tuple[np.ndarray, DenseJacobian]:
    r = np.array([10.0 * (x[1] - x[0] ** 2), 1.0 - x[0]])
    jac = np.array([[-20.0 * x[0], 10.0], [-1.0, 0.0]])
    return r, DenseJacobian(jac)


def test_unconstrained_minimum_found():
    result = solve(_rosenbrock, np.array([-1.2, 1.0]))
    assert result.converged
    np.testing.assert_allclose(result.x, [1.0, 1.0], atol=1e-9)
    assert result.cost < 1e-20


def test_active_bound_matches_scipy():
    lower, upper = np.array([-2.0, -2.0]), np.array([0.5, 2.0])
    result = solve(_rosenbrock, np.array([-1.2, 1.0]), lower, upper)
    reference = scipy.optimize.least_squares(lambda x: _rosenbrock(x)[0], [-1.2, 1.0],
                                             jac=lambda x: _rosenbrock(x)[1].matrix, bounds=(lower, upper),
                                             xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert result.converged
    assert result.x[0] == pytest.approx(0.5, abs=1e-12)  # on the bound
    np.testing.assert_allclose(result.x, reference.x, atol=1e-8)


def test_evaluation_budget_reported_as_not_converged():
    result = solve(_rosenbrock, np.array([-1.2, 1.0]), tolerances=Tolerances(max_evaluations=3))
    assert not result.converged
    assert result.status == "maximum evaluations reached"


def _freudenstein_roth(x: np.ndarray) -> tuple[np.ndarray, DenseJacobian]:
    r = np.array([-13 + x[0] + ((5 - x[1]) * x[1] - 2) * x[1], -29 + x[0] + ((x[1] + 1) * x[1] - 14) * x[1]])
    jac = np.array([[1.0, -3 * x[1] ** 2 + 10 * x[1] - 2], [1.0, 3 * x[1] ** 2 + 2 * x[1] - 14]])
    return r, DenseJacobian(jac)


def test_small_damped_decrease_is_not_convergence():
    """Freudenstein-Roth from (0.5, -2) with a loose function tolerance: after rejected steps
    the damping is large and an accepted step lowers the cost by less than ftol although
    Gauss-Newton still predicts more; that must not count as converged (it stopped at
    (11.46, -0.892) before, 0.05 from the local minimum (11.4128, -0.89681))."""
    result = solve(_freudenstein_roth, np.array([0.5, -2.0]), tolerances=Tolerances(ftol=1e-3, xtol=1e-12, gtol=1e-12))
    assert result.converged
    np.testing.assert_allclose(result.x, [11.41277900, -0.89680525], atol=1e-4)
    assert result.cost == pytest.approx(48.98425367924, rel=1e-9)


def test_step_re_solved_on_reached_bounds_keeps_the_model_decrease():
    """A variable whose damped step would cross its bound stops on it and the others are
    solved again: the linear model decreases at least as much as with the step clipped."""
    from nmsm.core.backends.levenberg_marquardt import bounded_step

    rng = np.random.default_rng(3)
    for _ in range(20):
        a = rng.normal(size=(12, 6)) @ np.diag([1, 1, 1, 3, 0.3, 2])
        r = rng.normal(size=12)
        jac = DenseJacobian(a)
        x = np.zeros(6)
        lower, upper = np.full(6, -0.2), np.full(6, 0.2)
        g, diag = jac.gradient(r), jac.normal_diagonal()
        free = np.ones(6, dtype=bool)

        def model_decrease(step):
            return -(2.0 * g @ step + jac.squared_norm_of_product(step))

        clipped = np.clip(jac.damped_step(g, free, 1e-6, diag), lower, upper)
        bounded = np.clip(bounded_step(jac, g, free, 1e-6, diag, x, lower, upper), lower, upper)
        assert model_decrease(bounded) >= model_decrease(clipped) - 1e-12


class _FreudensteinRoth(ResidualProblem):
    """A ResidualProblem with a dense Jacobian, bounded so that a bound is active."""

    name = "freudenstein_roth"

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([-10.0, -10.0]), np.array([10.0, 3.5])

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, DenseJacobian]:
        return _freudenstein_roth(x)


def test_the_backend_solves_a_residual_problem_as_the_algorithm_does():
    problem = _FreudensteinRoth()
    x0 = np.array([0.5, -2.0])
    direct = solve(problem.evaluate, x0, *problem.bounds(), Tolerances(ftol=1e-10))
    solution = get_backend("levenberg_marquardt").solve(problem, initial_guess=x0, ftol=1e-10)
    assert solution.backend == "levenberg_marquardt" and solution.success == direct.converged
    np.testing.assert_array_equal(solution.x_scaled, direct.x)
    np.testing.assert_array_equal(solution["x"], direct.x)
    assert solution.cost == direct.cost and solution.term_costs == {"freudenstein_roth": direct.cost}
    assert (solution.iterations, solution.evaluations, solution.status) == (direct.iterations, direct.evaluations,
                                                                            direct.status)
    with pytest.raises(TypeError, match="solved from initial_guess"):
        get_backend("levenberg_marquardt").solve(problem)
    with pytest.raises(TypeError, match="unknown levenberg_marquardt options: max_nfev"):
        get_backend("levenberg_marquardt").solve(problem, initial_guess=x0, max_nfev=3)

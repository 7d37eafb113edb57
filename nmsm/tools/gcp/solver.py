"""Solve a GCP task: bound-constrained Levenberg-Marquardt with exact CasADi Jacobians.

GCP problems have many more residuals than variables (e.g. 13 000 x 330 for the
tutorial's 8 x 15 grid), so each step is taken on the small normal matrix ``J^T J``
(Cholesky) instead of a factorization of ``J`` (scipy's ``trf`` 'exact' solver takes an
SVD of the whole Jacobian every iteration, several times slower here). The algorithm is
:func:`nmsm.tools.jmp.levenberg_marquardt.solve`; the Jacobian is evaluated only at
accepted points (:class:`LazyNormalJacobian`).

Settings mapping (lsqnonlin names): ``max_iterations`` -> iterations (each one Jacobian),
``max_function_evaluations`` -> residual evaluations, ``function_tolerance`` -> relative
cost decrease of an accepted step, ``step_tolerance`` -> relative step size,
``optimality_tolerance`` -> projected gradient ``|J^T r|_inf`` relative to its initial value
(at least 1).
"""

from __future__ import annotations

import time
from typing import Any

import attrs
import casadi as cs
import numpy as np
import scipy.linalg
import scipy.sparse

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.tools.jmp.levenberg_marquardt import Tolerances, solve


def _sparse(value: cs.DM) -> scipy.sparse.csc_matrix:
    sp = value.sparsity()
    return scipy.sparse.csc_matrix((np.asarray(value.nonzeros(), dtype=float), np.asarray(sp.row()),
                                    np.asarray(sp.colind())), shape=(sp.size1(), sp.size2()))


@attrs.define
class LazyNormalJacobian:
    """A Jacobian evaluated on first use, kept as ``J`` (sparse) and ``J^T J`` (dense)."""

    evaluate: Any
    x: np.ndarray
    free: np.ndarray
    _matrix: scipy.sparse.csc_matrix | None = None
    _normal: np.ndarray | None = None

    def _ensure(self) -> None:
        if self._matrix is None:
            full = self.x.copy()
            self._matrix = self.evaluate(full)[:, self.free]
            self._normal = np.asarray((self._matrix.T @ self._matrix).todense())

    def gradient(self, r: np.ndarray) -> np.ndarray:
        self._ensure()
        return np.asarray(self._matrix.T @ r).ravel()

    def normal_diagonal(self) -> np.ndarray:
        self._ensure()
        return np.diag(self._normal).copy()

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        self._ensure()
        idx = np.flatnonzero(free)
        step = np.zeros_like(g)
        if idx.size == 0:
            return step
        a = self._normal[np.ix_(idx, idx)].copy()
        a[np.diag_indices_from(a)] += mu * diag[idx]
        try:
            step[idx] = -scipy.linalg.cho_solve(scipy.linalg.cho_factor(a), g[idx])
        except np.linalg.LinAlgError:
            step[idx] = -np.linalg.lstsq(a, g[idx], rcond=None)[0]
        return step

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        self._ensure()
        return float(s @ self._normal @ s)


def solve_task(problem: OptimizationProblem, *, max_iterations: int, max_evaluations: int, ftol: float,
               xtol: float, gtol: float, verbose: bool = False) -> Solution:
    """Solve ``problem`` (bounds only) and return a :class:`~nmsm.core.problem.Solution`."""
    xs, ps = problem.scaled_vector(), problem.parameter_vector()
    r = problem.residual_vector()
    f_res = cs.Function("residuals", [xs, ps], [r])
    f_jac = cs.Function("jacobian", [xs, ps], [cs.jacobian(r, xs)])
    p = problem.parameter_values()
    lower, upper = problem.bounds_scaled()
    x0 = np.clip(problem.initial_scaled(), lower, upper)
    free = lower < upper
    base = x0.copy()

    def full(x_free: np.ndarray) -> np.ndarray:
        x = base.copy()
        x[free] = x_free
        return x

    def fun(x_free: np.ndarray) -> tuple[np.ndarray, LazyNormalJacobian]:
        x = full(x_free)
        residuals = np.asarray(f_res(x, p)).ravel()
        return residuals, LazyNormalJacobian(lambda xx: _sparse(f_jac(xx, p)), x, free)

    start = time.perf_counter()
    if not free.any() or r.numel() == 0:
        x_opt, status, iterations, success = x0, "nothing to optimize", 0, True
    else:
        r0, j0 = fun(x0[free])
        g0 = float(np.max(np.abs(j0.gradient(r0)), initial=0.0))
        tolerances = Tolerances(xtol=xtol, ftol=ftol, gtol=gtol * max(1.0, g0), max_iterations=max_iterations,
                                max_evaluations=max_evaluations)

        def report(iteration: int, cost: float, x: np.ndarray) -> None:
            if verbose:
                print(f"  iteration {iteration:3d}  cost {cost:.6g}  ({time.perf_counter() - start:.1f} s)")

        result = solve(fun, x0[free], lower[free], upper[free], tolerances, callback=report)
        x_opt, status, iterations, success = full(result.x), result.status, result.iterations, result.converged
    wall = time.perf_counter() - start
    term_costs = problem.term_costs(x_opt)
    return Solution(values=problem.unpack(x_opt), cost=float(sum(term_costs.values())), term_costs=term_costs,
                    success=success, status=status, iterations=iterations, wall_time=wall,
                    backend="gcp_levenberg_marquardt", x_scaled=x_opt)

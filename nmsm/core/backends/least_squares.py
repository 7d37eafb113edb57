"""Least-squares back end: scipy ``least_squares`` with exact, sparse CasADi Jacobians.

For problems whose objective is a sum of squared residuals with bounds only (JMP, MTLI,
GCP). scipy minimizes ``0.5 * sum(r**2)``; the reported cost is ``sum(r**2)`` like the
IPOPT back end.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, ClassVar

import casadi as cs
import numpy as np
import scipy.optimize
import scipy.sparse

from nmsm.core.backends.base import Backend
from nmsm.core.backends.sparse import SparseOutput
from nmsm.core.convergence import ConvergenceHistory
from nmsm.core.solution import Solution
from nmsm.core.progress import with_least_squares_progress

if TYPE_CHECKING:
    from nmsm.core.problem import OptimizationProblem


def solve_least_squares(
    problem: OptimizationProblem,
    *,
    ftol: float = 1e-8,
    xtol: float = 1e-8,
    gtol: float = 1e-8,
    max_nfev: int | None = None,
    verbose: int = 0,
    method: str = "trf",
    tr_solver: str | None = None,
    loss: str = "linear",
    **extra: Any,
) -> Solution:
    """Solve ``problem`` (no constraints allowed) and return a :class:`Solution`.

    ``tr_solver`` defaults to 'lsmr' (sparse) when the Jacobian is large, else 'exact'.
    """
    if problem.constraints:
        names = ", ".join(c.name for c in problem.constraints[:5])
        raise ValueError(
            f"problem '{problem.name}' has constraints ({names}); the least-squares back end "
            "handles bounds only: use backend='ipopt'"
        )
    if extra:
        raise TypeError(f"unknown least-squares options: {', '.join(extra)}")
    problem.require_no_lifted_parameters("least_squares")
    xs = problem.scaled_vector()
    ps = problem.parameter_vector()
    r = problem.residual_vector()
    f_res = cs.Function("residuals", [xs, ps], [r])
    jacobian = SparseOutput(cs.Function("jacobian", [xs, ps], [cs.jacobian(r, xs)]))
    p = problem.parameter_values()
    x0 = problem.initial_scaled()
    lo, hi = problem.bounds_scaled()
    x0 = np.clip(x0, lo, hi)
    # scipy requires a strictly interior start for 'trf'
    interior = (lo < hi)
    eps = 1e-10 * np.maximum(1.0, np.abs(x0))
    x0 = np.where(interior & (x0 <= lo), np.minimum(lo + eps, hi), x0)
    x0 = np.where(interior & (x0 >= hi), np.maximum(hi - eps, lo), x0)
    fixed = ~interior
    free_idx = np.flatnonzero(~fixed)

    def full(xf: np.ndarray) -> np.ndarray:
        x = x0.copy()
        x[free_idx] = xf
        return x

    def fun(xf: np.ndarray) -> np.ndarray:
        return np.asarray(f_res(full(xf), p).full()).ravel()

    n_res = r.numel()
    large = n_res * free_idx.size > 4_000_000
    solver = tr_solver or ("lsmr" if large else "exact")

    def jac(xf: np.ndarray) -> Any:
        J = jacobian(full(xf), p)[:, free_idx]
        return J if solver == "lsmr" else J.toarray()

    start = time.perf_counter()
    history = None
    if free_idx.size == 0 or n_res == 0:
        x_opt, status, nfev, success = x0, "nothing to optimize", 0, True
    else:
        fun, jac, history = record_history(fun, jac)
        if not verbose:
            fun, jac = with_least_squares_progress(problem.name, fun, jac)
        res = scipy.optimize.least_squares(
            fun, x0[free_idx], jac=jac, bounds=(lo[free_idx], hi[free_idx]), method=method,
            ftol=ftol, xtol=xtol, gtol=gtol, max_nfev=max_nfev, verbose=verbose,
            tr_solver=solver, loss=loss,
        )
        x_opt, status, nfev, success = full(res.x), res.message, int(res.nfev), bool(res.status > 0)
    wall = time.perf_counter() - start
    term_costs = problem.term_costs(x_opt)
    return Solution(
        values=problem.unpack(x_opt),
        cost=float(sum(term_costs.values())),
        term_costs=term_costs,
        success=success,
        status=str(status),
        iterations=nfev,
        wall_time=wall,
        backend="least_squares",
        x_scaled=x_opt,
        history=history.result() if history is not None else None,
    )


class LeastSquaresBackend(Backend):
    """scipy's ``least_squares`` (:func:`solve_least_squares`): the weighted residuals of an
    :class:`~nmsm.core.problem.OptimizationProblem` with bounds only, exact sparse Jacobians."""

    type: ClassVar[str] = "least_squares"

    def solve(self, problem: OptimizationProblem, **options: Any) -> Solution:
        return solve_least_squares(problem, **options)


class LeastSquaresHistory:
    """Per accepted iterate: ``sum(r**2)`` and the largest entry of the gradient ``J^T r``."""

    def __init__(self) -> None:
        self.cost: list[float] = []
        self.optimality: list[float] = []

    def result(self) -> ConvergenceHistory | None:
        return ConvergenceHistory(self.cost, optimality=self.optimality) if self.cost else None


def record_history(fun: Any, jac: Any) -> tuple[Any, Any, LeastSquaresHistory]:
    """``fun`` and ``jac`` for scipy's ``least_squares`` that record a :class:`LeastSquaresHistory`:
    scipy evaluates the Jacobian once per accepted iterate, at the point of the last residual
    evaluation."""
    history = LeastSquaresHistory()
    last = [np.full(1, np.nan)]

    def recording_fun(x: np.ndarray) -> np.ndarray:
        last[0] = r = fun(x)
        return r

    def recording_jac(x: np.ndarray) -> Any:
        J = jac(x)
        r = last[0]
        history.cost.append(float(np.dot(r, r)))
        gradient = np.asarray(J.T @ r).ravel()
        history.optimality.append(float(np.max(np.abs(gradient), initial=0.0)))
        return J

    return recording_fun, recording_jac, history

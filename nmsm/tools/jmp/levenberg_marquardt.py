"""Bound-constrained Levenberg-Marquardt for nonlinear least squares ``min sum(r(x)**2)``.

Used by inverse kinematics (one small dense problem per frame) and by Joint Model
Personalization (all frames' coordinates and the model parameters in one large sparse
problem). The Jacobian is exact (CasADi), so each iteration is a Gauss-Newton step
regularized by Marquardt's scaled damping ``mu * diag(J^T J)``:

    (J_f^T J_f + mu D_f) s_f = -J_f^T r

over the *free* variables ``f``: a variable sitting on a bound whose gradient pushes it
outwards is held there for the step (projected active set); every trial point is clipped
into the box. Damping follows Nielsen's rule (``mu`` shrinks by up to 3x after a good step,
doubles repeatedly after a rejected one).

Convergence (any of):

* ``|step|_inf <= xtol * (xtol + |x|_inf)``                          (step)
* ``cost - new_cost <= ftol * cost``  for an accepted step           (function)
* ``|projected gradient|_inf <= gtol``                               (first order)
* ``cost <= ctol``                                                   (exact fit)

``solve_dense`` takes numpy Jacobians; ``solve_sparse`` takes scipy sparse ones and
factorizes the damped normal matrix with SuperLU (fill-reducing column ordering), which
handles the block-arrow structure of JMP (per-frame coordinate blocks plus a few dense
parameter columns) in time linear in the number of frames.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import attrs
import numpy as np
import scipy.sparse
import scipy.sparse.linalg

#: ``x -> (r (m,), J (m, n))``
ResidualJacobian = Callable[[np.ndarray], tuple[np.ndarray, Any]]


@attrs.frozen
class LeastSquaresResult:
    """Outcome of a solve. ``cost = sum(r**2)`` at ``x``; ``status`` says why it stopped."""

    x: np.ndarray
    residuals: np.ndarray
    cost: float
    iterations: int
    evaluations: int
    converged: bool
    status: str
    gradient_norm: float


@attrs.frozen(kw_only=True)
class Tolerances:
    """Stopping rules (see module docstring). ``max_evaluations`` counts residual+Jacobian evaluations."""

    xtol: float = 1e-10
    ftol: float = 1e-12
    gtol: float = 1e-12
    ctol: float = 0.0
    max_iterations: int = 200
    max_evaluations: int = 1000


def _dense_step(jtj: np.ndarray, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
    idx = np.flatnonzero(free)
    step = np.zeros_like(g)
    if idx.size == 0:
        return step
    a = jtj[np.ix_(idx, idx)].copy()
    a[np.diag_indices_from(a)] += mu * diag[idx]
    try:
        step[idx] = -np.linalg.solve(a, g[idx])
    except np.linalg.LinAlgError:
        step[idx] = -np.linalg.lstsq(a, g[idx], rcond=None)[0]
    return step


def _sparse_step(jtj: scipy.sparse.csc_matrix, g: np.ndarray, free: np.ndarray, mu: float,
                 diag: np.ndarray) -> np.ndarray:
    idx = np.flatnonzero(free)
    step = np.zeros_like(g)
    if idx.size == 0:
        return step
    a = jtj[idx][:, idx] + scipy.sparse.diags(mu * diag[idx])
    lu = scipy.sparse.linalg.splu(scipy.sparse.csc_matrix(a), permc_spec="COLAMD")
    step[idx] = -lu.solve(g[idx])
    return step


def _solve(fun: ResidualJacobian, x0: np.ndarray, lower: np.ndarray, upper: np.ndarray,
           tol: Tolerances, sparse: bool, callback: Callable[[int, float, np.ndarray], None] | None) -> LeastSquaresResult:
    lower = np.broadcast_to(np.asarray(lower, dtype=float), x0.shape)
    upper = np.broadcast_to(np.asarray(upper, dtype=float), x0.shape)
    if np.any(lower > upper):
        raise ValueError("a lower bound is above its upper bound")
    x = np.clip(np.asarray(x0, dtype=float), lower, upper)
    r, jac = fun(x)
    evaluations = 1
    cost = float(r @ r)
    mu: float | None = None
    nu = 2.0
    status = "maximum iterations reached"
    converged = False
    pg_norm = np.inf
    iteration = 0
    for iteration in range(1, tol.max_iterations + 1):
        g = np.asarray(jac.T @ r).ravel()
        jtj = (jac.T @ jac).tocsc() if sparse else jac.T @ jac
        span = np.maximum(1e-12, 1e-12 * np.abs(x))
        at_lower = x <= lower + span
        at_upper = x >= upper - span
        fixed = lower == upper
        active = fixed | (at_lower & (g > 0)) | (at_upper & (g < 0))
        free = ~active
        pg_norm = float(np.max(np.abs(g[free]), initial=0.0))
        if cost <= tol.ctol:
            status, converged = "cost below ctol", True
            break
        if pg_norm <= tol.gtol:
            status, converged = "projected gradient below gtol", True
            break
        diag = np.asarray(jtj.diagonal()).ravel().copy()
        dmax = float(np.max(diag[free], initial=0.0))
        diag = np.maximum(diag, max(dmax, 1e-300) * 1e-10)
        if mu is None:
            mu = 1e-3
        accepted = False
        exhausted = False
        while True:
            step = (_sparse_step if sparse else _dense_step)(jtj, g, free, mu, diag)
            trial = np.clip(x + step, lower, upper)
            step = trial - x
            if float(np.max(np.abs(step), initial=0.0)) <= tol.xtol * (tol.xtol + float(np.max(np.abs(x), initial=0.0))):
                status, converged = "step below xtol", True
                break
            predicted = -(2.0 * float(g @ step) + float(step @ (jtj @ step)))
            r_new, jac_new = fun(trial)
            evaluations += 1
            cost_new = float(r_new @ r_new)
            actual = cost - cost_new
            if np.isfinite(cost_new) and actual > 0.0:
                rho = actual / predicted if predicted > 0 else 0.0
                mu *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                nu = 2.0
                previous = cost
                x, r, jac, cost = trial, r_new, jac_new, cost_new
                accepted = True
                if actual <= tol.ftol * previous:
                    status, converged = "cost change below ftol", True
                break
            mu *= nu
            nu *= 2.0
            if evaluations >= tol.max_evaluations:
                exhausted = True
                break
            if mu > 1e20:
                status, converged = "no decrease possible (machine precision)", True
                break
        if callback is not None:
            callback(iteration, cost, x)
        if converged:
            break
        if exhausted or evaluations >= tol.max_evaluations:
            status = "maximum evaluations reached"
            break
    return LeastSquaresResult(x=x, residuals=r, cost=cost, iterations=iteration, evaluations=evaluations,
                              converged=converged, status=status, gradient_norm=pg_norm)


def solve_dense(fun: ResidualJacobian, x0: np.ndarray, lower: Any = -np.inf, upper: Any = np.inf,
                tolerances: Tolerances = Tolerances(),
                callback: Callable[[int, float, np.ndarray], None] | None = None) -> LeastSquaresResult:
    """Minimize ``sum(r(x)**2)`` subject to ``lower <= x <= upper``; ``fun`` returns dense ``J``."""
    return _solve(fun, np.asarray(x0, dtype=float), lower, upper, tolerances, False, callback)


def solve_sparse(fun: ResidualJacobian, x0: np.ndarray, lower: Any = -np.inf, upper: Any = np.inf,
                 tolerances: Tolerances = Tolerances(),
                 callback: Callable[[int, float, np.ndarray], None] | None = None) -> LeastSquaresResult:
    """As :func:`solve_dense` with ``J`` a scipy sparse matrix (for thousands of variables)."""
    return _solve(fun, np.asarray(x0, dtype=float), lower, upper, tolerances, True, callback)

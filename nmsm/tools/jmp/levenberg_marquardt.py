"""Bound-constrained Levenberg-Marquardt for nonlinear least squares ``min sum(r(x)**2)``.

Used by inverse kinematics (one small dense problem per frame) and by Joint Model
Personalization (all frames' coordinates and the model parameters together). The
Jacobian is exact (CasADi), so each iteration is a Gauss-Newton step regularized by
Marquardt's scaled damping ``mu * diag(J^T J)``:

    (J_f^T J_f + mu D_f) s_f = -J_f^T r

over the *free* variables ``f``: a variable sitting on a bound whose gradient pushes it
outwards is held there for the step (projected active set); a variable whose step would
cross its bound stops on it and the step of the others is solved again
(:func:`bounded_step`). Damping follows Nielsen's rule (``mu`` shrinks by up to 3x after a
good step, doubles repeatedly after a rejected one).

Convergence (any of):

* ``|step|_inf <= xtol * (xtol + |x|_inf)``                          (step)
* ``cost - new_cost <= ftol * cost``  for an accepted step, and the  (function)
  decrease the Gauss-Newton step within the box predicts from there is below it too
  (a heavily damped step decreases little however far the minimum is)
* ``|projected J^T r|_inf <= gtol``                                 (first order)
* ``cost <= ctol``                                                   (exact fit)

The linear algebra is pluggable: ``fun(x)`` returns ``(r, J)`` with ``J`` one of

* :class:`DenseJacobian` (numpy, small problems: IK frames);
* :class:`SparseJacobian` (scipy sparse; SuperLU on the damped normal matrix);
* :class:`BlockArrowJacobian` (JMP: per-frame blocks ``dr_f/dq_f`` and ``dr_f/dp`` with
  ``x = [q_1, ..., q_F, p]``), solved by the Schur complement on the shared parameters in
  time linear in the number of frames.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import attrs
import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from nmsm.core.convergence import ConvergenceHistory


class Jacobian(Protocol):
    """What the algorithm needs from a Jacobian ``J`` (m x n)."""

    def gradient(self, r: np.ndarray) -> np.ndarray:
        """``J^T r`` (n,)."""

    def normal_diagonal(self) -> np.ndarray:
        """``diag(J^T J)`` (n,)."""

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        """``s`` with ``(J^T J + mu diag(diag))_ff s_f = -g_f`` and ``s = 0`` off ``free``."""

    def product(self, s: np.ndarray) -> np.ndarray:
        """``J s`` (m,)."""

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        """``|J s|^2``."""


@attrs.frozen
class DenseJacobian:
    """A numpy Jacobian ``(m, n)``."""

    matrix: np.ndarray

    def gradient(self, r: np.ndarray) -> np.ndarray:
        return self.matrix.T @ r

    def normal_diagonal(self) -> np.ndarray:
        return np.einsum("ij,ij->j", self.matrix, self.matrix)

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        idx = np.flatnonzero(free)
        step = np.zeros_like(g)
        if idx.size == 0:
            return step
        j = self.matrix[:, idx]
        a = j.T @ j
        a[np.diag_indices_from(a)] += mu * diag[idx]
        try:
            step[idx] = -np.linalg.solve(a, g[idx])
        except np.linalg.LinAlgError:
            step[idx] = -np.linalg.lstsq(a, g[idx], rcond=None)[0]
        return step

    def product(self, s: np.ndarray) -> np.ndarray:
        return np.asarray(self.matrix @ s).ravel()

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        v = self.product(s)
        return float(v @ v)


@attrs.frozen
class SparseJacobian:
    """A scipy sparse Jacobian ``(m, n)``."""

    matrix: scipy.sparse.csc_matrix

    def gradient(self, r: np.ndarray) -> np.ndarray:
        return np.asarray(self.matrix.T @ r).ravel()

    def normal_diagonal(self) -> np.ndarray:
        return np.asarray(self.matrix.multiply(self.matrix).sum(axis=0)).ravel()

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        idx = np.flatnonzero(free)
        step = np.zeros_like(g)
        if idx.size == 0:
            return step
        j = self.matrix[:, idx]
        a = (j.T @ j).tocsc() + scipy.sparse.diags(mu * diag[idx], format="csc")
        step[idx] = -scipy.sparse.linalg.splu(a, permc_spec="COLAMD").solve(g[idx])
        return step

    def product(self, s: np.ndarray) -> np.ndarray:
        return np.asarray(self.matrix @ s).ravel()

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        v = self.product(s)
        return float(v @ v)


@attrs.frozen
class BlockArrowJacobian:
    """Jacobian of residuals ``r = [r_1; ...; r_F]`` (``r_f``: m each) in ``x = [q_1 .. q_F, p]``
    where ``r_f`` depends on ``q_f`` (n each) and ``p`` (k) only.

    ``dq`` ``(F, m, n)`` = dr_f/dq_f; ``dp`` ``(F, m, k)`` = dr_f/dp.
    """

    dq: np.ndarray = attrs.field(converter=np.ascontiguousarray)
    dp: np.ndarray = attrs.field(converter=np.ascontiguousarray)

    @property
    def shape(self) -> tuple[int, int, int, int]:
        f, m, n = self.dq.shape
        return f, m, n, self.dp.shape[2]

    def gradient(self, r: np.ndarray) -> np.ndarray:
        f, m, n, k = self.shape
        rr = r.reshape(f, m)
        return np.concatenate([np.einsum("fmn,fm->fn", self.dq, rr).ravel(), np.einsum("fmk,fm->k", self.dp, rr)])

    def normal_diagonal(self) -> np.ndarray:
        return np.concatenate([np.einsum("fmn,fmn->fn", self.dq, self.dq).ravel(),
                               np.einsum("fmk,fmk->k", self.dp, self.dp)])

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        f, m, n, k = self.shape
        free_q = free[: f * n].reshape(f, n).astype(float)
        free_p = free[f * n:].astype(float)
        # stacked small products (one per frame): BLAS stays single-threaded at these sizes,
        # which is much faster than one large threaded product on a busy machine
        dq = self.dq * free_q[:, None, :]
        dp = self.dp * free_p[None, None, :]
        dq_t = dq.transpose(0, 2, 1)
        a = dq_t @ dq
        b = dq_t @ dp
        c = (dp.transpose(0, 2, 1) @ dp).sum(axis=0)
        dq_diag = (mu * diag[: f * n].reshape(f, n)) * free_q + (1.0 - free_q)
        a[:, np.arange(n), np.arange(n)] += dq_diag
        c[np.arange(k), np.arange(k)] += mu * diag[f * n:] * free_p + (1.0 - free_p)
        gq = g[: f * n].reshape(f, n) * free_q
        gp = g[f * n:] * free_p
        if k == 0:
            return -np.linalg.solve(a, gq[:, :, None])[:, :, 0].ravel()
        solved = np.linalg.solve(a, np.concatenate([b, gq[:, :, None]], axis=2))
        x_b, y = solved[:, :, :k], solved[:, :, k]
        b_t = b.transpose(0, 2, 1)
        schur = c - (b_t @ x_b).sum(axis=0)
        rhs = -gp + (b_t @ y[:, :, None]).sum(axis=0)[:, 0]
        step_p = np.linalg.solve(schur, rhs)
        step_q = -(y + x_b @ step_p)
        return np.concatenate([step_q.ravel(), step_p]) * free

    def product(self, s: np.ndarray) -> np.ndarray:
        f, m, n, k = self.shape
        v = np.einsum("fmn,fn->fm", self.dq, s[: f * n].reshape(f, n)) + np.einsum("fmk,k->fm", self.dp, s[f * n:])
        return v.ravel()

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        v = self.product(s)
        return float(v @ v)


#: damping of the Gauss-Newton step that tests the function tolerance (relative to diag(J^T J))
GAUSS_NEWTON_DAMPING = 1e-12
#: largest number of re-solves of one step as variables reach their bounds
MAX_BOUND_PASSES = 20


def bounded_step(jac: Jacobian, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray, x: np.ndarray,
                 lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The damped step ``s`` (n,) of the linear model restricted to the box.

    Variables whose step would cross a bound are stopped on it, and the step of the others is
    solved again with those displacements given, minimizing
    ``|r + J_f s_f + J_b s_b|^2 + mu s_f^T D_f s_f`` over the still free ``f`` (``s_b`` the
    displacements to the bounds), until no free variable crosses. A step merely clipped to
    the box is not a minimizer of the model on the box: its predicted decrease is poor, so
    the damping grows and the iterations crawl while any of the problem's many variables
    (a coordinate on its range limit in one frame of a JMP trial) presses on a bound.
    """
    free = free.copy()
    pinned = np.zeros_like(x)
    step = jac.damped_step(g, free, mu, diag)
    for _ in range(MAX_BOUND_PASSES):
        trial = x + step
        crossing = free & ((trial < lower) | (trial > upper))
        if not crossing.any():
            break
        pinned[crossing] = np.clip(trial[crossing], lower[crossing], upper[crossing]) - x[crossing]
        free &= ~crossing
        step = jac.damped_step(g + jac.gradient(jac.product(pinned)), free, mu, diag) + pinned
    return step


def _damping_diagonal(jac: Jacobian, free: np.ndarray) -> np.ndarray:
    """Marquardt's scaling ``diag(J^T J)``, floored at 1e-10 of its largest free entry."""
    diag = jac.normal_diagonal()
    return np.maximum(diag, max(float(np.max(diag[free], initial=0.0)), 1e-300) * 1e-10)


def _gauss_newton_decrease(jac: Jacobian, r: np.ndarray, x: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                           fixed: np.ndarray) -> float:
    """Decrease of ``|r|^2`` that the (nearly undamped) Gauss-Newton step within the box
    predicts from ``x``: how much the linear model says is still to gain. A small accepted
    decrease means convergence only when this is small too; otherwise the step was small
    because the damping was large."""
    g = jac.gradient(r)
    span = np.maximum(1e-12, 1e-12 * np.abs(x))
    free = ~(fixed | ((x <= lower + span) & (g > 0)) | ((x >= upper - span) & (g < 0)))
    diag = _damping_diagonal(jac, free)
    step = np.clip(x + bounded_step(jac, g, free, GAUSS_NEWTON_DAMPING, diag, x, lower, upper), lower, upper) - x
    return max(0.0, -(2.0 * float(g @ step) + jac.squared_norm_of_product(step)))


#: ``x -> (r (m,), J)``
ResidualJacobian = Callable[[np.ndarray], tuple[np.ndarray, Jacobian]]


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
    history: ConvergenceHistory | None = None


@attrs.frozen(kw_only=True)
class Tolerances:
    """Stopping rules (see module docstring). ``max_evaluations`` counts residual+Jacobian evaluations."""

    xtol: float = 1e-10
    ftol: float = 1e-12
    gtol: float = 1e-12
    ctol: float = 0.0
    max_iterations: int = 200
    max_evaluations: int = 1000


def solve(fun: ResidualJacobian, x0: np.ndarray, lower: Any = -np.inf, upper: Any = np.inf,
          tolerances: Tolerances = Tolerances(),
          callback: Callable[[int, float, np.ndarray], None] | None = None) -> LeastSquaresResult:
    """Minimize ``sum(r(x)**2)`` subject to ``lower <= x <= upper`` (see module docstring).

    ``callback(iteration, cost, x)`` is called after every iteration.
    """
    tol = tolerances
    x0 = np.asarray(x0, dtype=float)
    lower = np.broadcast_to(np.asarray(lower, dtype=float), x0.shape)
    upper = np.broadcast_to(np.asarray(upper, dtype=float), x0.shape)
    if np.any(lower > upper):
        raise ValueError("a lower bound is above its upper bound")
    x = np.clip(x0, lower, upper)
    r, jac = fun(x)
    evaluations = 1
    cost = float(r @ r)
    mu = 1e-3
    nu = 2.0
    status = "maximum iterations reached"
    converged = False
    pg_norm = np.inf
    iteration = 0
    fixed = lower == upper
    costs: list[float] = []
    gradients: list[float] = []
    for iteration in range(1, tol.max_iterations + 1):
        g = jac.gradient(r)
        span = np.maximum(1e-12, 1e-12 * np.abs(x))
        active = fixed | ((x <= lower + span) & (g > 0)) | ((x >= upper - span) & (g < 0))
        free = ~active
        pg_norm = float(np.max(np.abs(g[free]), initial=0.0))
        costs.append(cost)
        gradients.append(pg_norm)
        if cost <= tol.ctol:
            status, converged = "cost below ctol", True
            break
        if pg_norm <= tol.gtol:
            status, converged = "projected gradient below gtol", True
            break
        diag = _damping_diagonal(jac, free)
        accepted = exhausted = False
        while True:
            step = bounded_step(jac, g, free, mu, diag, x, lower, upper)
            trial = np.clip(x + step, lower, upper)
            step = trial - x
            if float(np.max(np.abs(step), initial=0.0)) <= tol.xtol * (tol.xtol + float(np.max(np.abs(x), initial=0.0))):
                status, converged = "step below xtol", True
                break
            predicted = -(2.0 * float(g @ step) + jac.squared_norm_of_product(step))
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
                if (actual <= tol.ftol * previous
                        and _gauss_newton_decrease(jac, r, x, lower, upper, fixed) <= tol.ftol * previous):
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
        if callback is not None and accepted:
            callback(iteration, cost, x)
        if converged:
            break
        if exhausted or evaluations >= tol.max_evaluations:
            status = "maximum evaluations reached"
            break
    if costs and cost != costs[-1]:  # the last accepted step's point (its gradient not evaluated)
        costs.append(cost)
        gradients.append(float("nan"))
    return LeastSquaresResult(x=x, residuals=r, cost=cost, iterations=iteration, evaluations=evaluations,
                              converged=converged, status=status, gradient_norm=pg_norm,
                              history=ConvergenceHistory(costs, optimality=gradients) if costs else None)

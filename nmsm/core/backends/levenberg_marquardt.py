"""Bound-constrained Levenberg-Marquardt for nonlinear least squares ``min sum(r(x)**2)``:
the back end ``levenberg_marquardt``.

The back end (:class:`LevenbergMarquardtBackend`) solves a
:class:`~nmsm.core.residual_problem.ResidualProblem` (Joint Model Personalization: all
frames' coordinates and the model parameters together, a block-arrow Jacobian) or the
weighted residuals of an :class:`~nmsm.core.problem.OptimizationProblem` with bounds only
(a sparse Jacobian in the scaled variables). :func:`solve` is the algorithm on a function
``x -> (r, J)``; inverse kinematics calls it on one small dense problem per frame. The
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

The linear algebra is the Jacobian's: ``fun(x)`` returns ``(r, J)`` with ``J`` one of
:mod:`nmsm.core.jacobians` (dense, sparse, block-arrow).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

import attrs
import casadi as cs
import numpy as np

from nmsm.core.backends.base import Backend
from nmsm.core.backends.sparse import SparseOutput
from nmsm.core.convergence import ConvergenceHistory
from nmsm.core.jacobians import Jacobian, SparseJacobian
from nmsm.core.residual_problem import ResidualProblem
from nmsm.core.solution import Solution

if TYPE_CHECKING:
    from nmsm.core.problem import OptimizationProblem


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


class OptimizationResiduals(ResidualProblem):
    """The weighted residuals of an :class:`~nmsm.core.problem.OptimizationProblem` (bounds
    only) as a :class:`~nmsm.core.residual_problem.ResidualProblem` in its scaled variables,
    with a :class:`~nmsm.core.jacobians.SparseJacobian`."""

    def __init__(self, problem: OptimizationProblem) -> None:
        if problem.constraints:
            names = ", ".join(c.name for c in problem.constraints[:5])
            raise ValueError(f"problem '{problem.name}' has constraints ({names}); the levenberg_marquardt back end "
                             "handles bounds only: use backend='ipopt'")
        problem.require_no_lifted_parameters("levenberg_marquardt")
        self.problem = problem
        self.name = problem.name
        xs, ps = problem.scaled_vector(), problem.parameter_vector()
        r = problem.residual_vector()
        self._residuals = cs.Function("residuals", [xs, ps], [r])
        self._jacobian = SparseOutput(cs.Function("jacobian", [xs, ps], [cs.jacobian(r, xs)]))
        self._p = problem.parameter_values()

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.problem.bounds_scaled()

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, Jacobian]:
        r = np.asarray(self._residuals(x, self._p)).ravel()
        return r, SparseJacobian(self._jacobian(x, self._p))

    def values(self, x: np.ndarray) -> dict[str, np.ndarray]:
        return self.problem.unpack(x)

    def costs(self, x: np.ndarray) -> dict[str, float]:
        return self.problem.term_costs(x)


class LevenbergMarquardtBackend(Backend):
    """Bound-constrained Levenberg-Marquardt with exact Jacobians (module docstring), on a
    :class:`~nmsm.core.residual_problem.ResidualProblem` or an
    :class:`~nmsm.core.problem.OptimizationProblem` with bounds only.

    Options: the stopping rules of :class:`Tolerances` (``xtol``, ``ftol``, ``gtol``, ``ctol``,
    ``max_iterations``, ``max_evaluations``), ``initial_guess`` (the start ``x`` (n,); required
    for a ``ResidualProblem``, the scaled initial values of an ``OptimizationProblem`` by
    default) and ``callback(iteration, cost, x)`` after every accepted iteration. The
    :class:`~nmsm.core.solution.Solution`'s ``cost`` is ``sum(r**2)``, ``iterations`` the
    iterations, ``evaluations`` the residual and Jacobian evaluations.
    """

    type: ClassVar[str] = "levenberg_marquardt"

    def solve(self, problem: ResidualProblem | OptimizationProblem, *, initial_guess: np.ndarray | None = None,
              callback: Callable[[int, float, np.ndarray], None] | None = None, **tolerances: Any) -> Solution:
        fields = [a.name for a in attrs.fields(Tolerances)]
        unknown = [name for name in tolerances if name not in fields]
        if unknown:
            raise TypeError(f"unknown levenberg_marquardt options: {', '.join(unknown)} (expected {', '.join(fields)}, "
                            "initial_guess, callback)")
        limits = Tolerances(**tolerances)
        if isinstance(problem, ResidualProblem):
            residuals = problem
            if initial_guess is None:
                raise TypeError(f"problem '{problem.name}': a ResidualProblem is solved from initial_guess=x0 (n,)")
        else:
            residuals = OptimizationResiduals(problem)
            if initial_guess is None:
                initial_guess = problem.initial_scaled()
        lower, upper = residuals.bounds()
        start = time.perf_counter()
        result = solve(residuals.evaluate, np.asarray(initial_guess, dtype=float), lower, upper, limits, callback)
        wall = time.perf_counter() - start
        return Solution(values=residuals.values(result.x), cost=result.cost, term_costs=residuals.costs(result.x),
                        success=result.converged, status=result.status, iterations=result.iterations,
                        wall_time=wall, backend=self.type, x_scaled=result.x, history=result.history,
                        evaluations=result.evaluations)

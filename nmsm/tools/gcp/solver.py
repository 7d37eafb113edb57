"""Solve a GCP task with exact Jacobians assembled by the chain rule through the foot
coordinates.

A task's residuals depend on the kinematic coefficients ``C`` only through each foot's
coordinates ``q = (N (base * C))^T`` and rates ``qdot``, which are linear in the scaled
variables ``x``: ``z(x) = G x + z0``. :func:`~nmsm.tools.gcp.problem.build_task_problem`
makes ``z`` problem parameters (``lifted``), so the residuals are ``r(x, z)`` and, exactly,

    dr/dx = r_x(x, z(x)) + r_z(x, z(x)) G

``r_z`` is cheap for CasADi: each frame's residuals depend on that frame's 14 coordinates
and rates only, so its forward mode needs about 14 directions through the per-frame map,
where differentiating through ``C`` directly needs one direction per colour of ``C`` (about
40). Measured on the tutorial's 8 x 15 grid: 0.7 s per Jacobian instead of 3.2 s.

The step computation is scipy's ``least_squares`` ('trf', LSMR trust-region steps, bounds),
as the core back end (:mod:`nmsm.core.backends.least_squares`) runs it; the problem's
lifted parameters are left at the solution's values.
"""

from __future__ import annotations

import time
import casadi as cs
import numpy as np
import scipy.optimize
import scipy.sparse

from nmsm.core.backends.least_squares import record_history
from nmsm.core.backends.sparse import SparseOutput, dm_to_csc
from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.progress import with_least_squares_progress
from nmsm.tools.gcp.blas_threads import single_threaded_blas
from nmsm.tools.gcp.problem import TaskProblem


class LiftedResiduals:
    """``r(x)`` and ``dr/dx`` of a task problem with lifted foot coordinates (module docstring)."""

    def __init__(self, task: TaskProblem) -> None:
        problem: OptimizationProblem = task.problem
        self.problem = problem
        xs, ps = problem.scaled_vector(), problem.parameter_vector()
        r = problem.residual_vector()
        names = list(task.lifted)
        symbols = [problem.parameters[n].symbol for n in names]
        z = cs.vertcat(*[cs.vec(s) for s in symbols]) if symbols else cs.MX(0, 1)
        z_of_x = cs.vertcat(*[cs.vec(task.lifted[n]) for n in names]) if names else cs.MX(0, 1)
        self.names = names
        self.f_residuals = cs.Function("residuals", [xs, ps], [r])
        self._jac_x = SparseOutput(cs.Function("jac_x", [xs, ps], [cs.jacobian(r, xs)]))
        self._jac_z = SparseOutput(cs.Function("jac_z", [xs, ps], [cs.jacobian(r, z)]))
        self.f_z = cs.Function("z", [xs], [z_of_x])
        self.lift_matrix = dm_to_csc(cs.Function("dz_dx", [xs], [cs.jacobian(z_of_x, xs)])(np.zeros(xs.numel())))
        index, start = {}, 0
        for p in problem.parameters.values():
            index[p.name] = (start, p.shape)
            start += p.shape[0] * p.shape[1]
        self.slices = [(index[n][0], index[n][0] + index[n][1][0] * index[n][1][1]) for n in names]
        self.static = problem.parameter_values()

    def parameters(self, x: np.ndarray) -> np.ndarray:
        """The parameter vector with the lifted coordinates at ``z(x)``."""
        p = self.static.copy()
        z = np.asarray(self.f_z(x)).ravel()
        offset = 0
        for lo, hi in self.slices:
            p[lo:hi] = z[offset: offset + hi - lo]
            offset += hi - lo
        return p

    def residuals(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(self.f_residuals(x, self.parameters(x))).ravel()

    def jacobian(self, x: np.ndarray) -> scipy.sparse.csc_matrix:
        p = self.parameters(x)
        jac = self._jac_x(x, p)
        if self.names:
            jac = jac + self._jac_z(x, p) @ self.lift_matrix
        return jac.tocsc()

    def store(self, x: np.ndarray) -> None:
        """Set the problem's lifted parameters to their values at ``x``."""
        p = self.parameters(x)
        for name, (lo, hi) in zip(self.names, self.slices):
            shape = self.problem.parameters[name].shape
            self.problem.set_parameter(name, p[lo:hi].reshape(shape, order="F"))


def solve_task(task: TaskProblem, *, ftol: float, xtol: float, gtol: float, max_nfev: int,
               verbose: int = 0) -> Solution:
    """Solve a built task (bounds only) and return a :class:`~nmsm.core.problem.Solution`."""
    problem = task.problem
    lifted = LiftedResiduals(task)
    x0 = problem.initial_scaled()
    lo, hi = problem.bounds_scaled()
    x0 = np.clip(x0, lo, hi)
    interior = lo < hi
    eps = 1e-10 * np.maximum(1.0, np.abs(x0))
    x0 = np.where(interior & (x0 <= lo), np.minimum(lo + eps, hi), x0)
    x0 = np.where(interior & (x0 >= hi), np.maximum(hi - eps, lo), x0)
    free = np.flatnonzero(interior)

    def full(xf: np.ndarray) -> np.ndarray:
        x = x0.copy()
        x[free] = xf
        return x

    def fun(xf: np.ndarray) -> np.ndarray:
        return lifted.residuals(full(xf))

    def jac(xf: np.ndarray) -> scipy.sparse.csc_matrix:
        return lifted.jacobian(full(xf))[:, free]

    start = time.perf_counter()
    history = None
    if free.size == 0:
        x_opt, status, nfev, success = x0, "nothing to optimize", 0, True
    else:
        fun, jac, history = record_history(fun, jac)
        if not verbose:
            fun, jac = with_least_squares_progress(problem.name, fun, jac)
        with single_threaded_blas():  # LSMR's many small BLAS calls (nmsm.tools.gcp.blas_threads)
            result = scipy.optimize.least_squares(
                fun, x0[free], jac=jac,
                bounds=(lo[free], hi[free]), method="trf", tr_solver="lsmr", ftol=ftol, xtol=xtol, gtol=gtol,
                max_nfev=max_nfev, verbose=verbose)
        x_opt, status, nfev, success = full(result.x), str(result.message), int(result.nfev), bool(result.status > 0)
    wall = time.perf_counter() - start
    lifted.store(x_opt)
    term_costs = problem.term_costs(x_opt)
    return Solution(values=problem.unpack(x_opt), cost=float(sum(term_costs.values())), term_costs=term_costs,
                    success=success, status=status, iterations=nfev, wall_time=wall,
                    backend="least_squares (lifted foot coordinates)", x_scaled=x_opt,
                    history=history.result() if history is not None else None)

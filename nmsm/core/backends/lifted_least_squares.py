"""The back end ``lifted_least_squares``: scipy's ``least_squares`` on a problem with lifted
parameters, exact Jacobians assembled by the chain rule through them.

A lifted parameter (:meth:`~nmsm.core.problem.OptimizationProblem.lifted_parameter`) stands
for an expression ``z(x)`` of the scaled design variables that is affine in them,
``z(x) = G x + z0`` (GCP: each foot's coordinates and rates, linear in the B-spline
coefficients). The residuals are written in terms of the parameter, ``r(x, z)``, and, exactly,

    dr/dx = r_x(x, z(x)) + r_z(x, z(x)) G

``r_z`` can be much cheaper for CasADi than differentiating through ``x`` directly: when each
sample's residuals depend on that sample's few entries of ``z`` only, its forward mode needs
about as many directions as a sample has entries, where differentiating through ``x`` needs
one direction per colour of the whole Jacobian. ``G`` is read once, at ``x = 0``.

The step computation is scipy's ``least_squares`` ('trf', LSMR trust-region steps, bounds
only), with OpenBLAS on one thread while it runs (:mod:`nmsm.core.blas_threads`). After the
solve the lifted parameters hold their values at the solution, so the problem evaluates
(``term_costs``, ``evaluate``) consistently there.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, ClassVar

import casadi as cs
import numpy as np
import scipy.optimize
import scipy.sparse

from nmsm.core.backends.base import Backend
from nmsm.core.backends.least_squares import record_history
from nmsm.core.backends.sparse import SparseOutput, dm_to_csc
from nmsm.core.blas_threads import single_threaded_blas
from nmsm.core.progress import with_least_squares_progress
from nmsm.core.solution import Solution

if TYPE_CHECKING:
    from nmsm.core.problem import OptimizationProblem


class LiftedResiduals:
    """``r(x)`` and ``dr/dx`` of a problem with lifted parameters (module docstring)."""

    def __init__(self, problem: OptimizationProblem) -> None:
        self.problem = problem
        xs, ps = problem.scaled_vector(), problem.parameter_vector()
        r = problem.residual_vector()
        names = list(problem.lifted)
        symbols = [problem.parameters[n].symbol for n in names]
        z = cs.vertcat(*[cs.vec(s) for s in symbols]) if symbols else cs.MX(0, 1)
        z_of_x = cs.vertcat(*[cs.vec(problem.lifted[n]) for n in names]) if names else cs.MX(0, 1)
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
        """The parameter vector with the lifted parameters at ``z(x)``."""
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


def solve_lifted_least_squares(problem: OptimizationProblem, *, ftol: float = 1e-8, xtol: float = 1e-8,
                               gtol: float = 1e-8, max_nfev: int | None = None, verbose: int = 0) -> Solution:
    """Solve ``problem`` (bounds only; lifted parameters optional) and return a
    :class:`~nmsm.core.solution.Solution`; options as scipy's ``least_squares``, whose
    ``max_nfev`` counts residual evaluations."""
    if problem.constraints:
        names = ", ".join(c.name for c in problem.constraints[:5])
        raise ValueError(f"problem '{problem.name}' has constraints ({names}); the lifted_least_squares back end "
                         "handles bounds only: use backend='ipopt'")
    lifted = LiftedResiduals(problem)
    x0 = problem.initial_scaled()
    lo, hi = problem.bounds_scaled()
    x0 = np.clip(x0, lo, hi)
    interior = lo < hi  # scipy's 'trf' needs a strictly interior start
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
        with single_threaded_blas():
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
                    backend=LiftedLeastSquaresBackend.type, x_scaled=x_opt,
                    history=history.result() if history is not None else None)


class LiftedLeastSquaresBackend(Backend):
    """scipy's ``least_squares`` with Jacobians through lifted parameters
    (:func:`solve_lifted_least_squares`)."""

    type: ClassVar[str] = "lifted_least_squares"

    def solve(self, problem: OptimizationProblem, **options: Any) -> Solution:
        return solve_lifted_least_squares(problem, **options)

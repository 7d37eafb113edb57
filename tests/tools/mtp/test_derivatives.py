"""Block-wise exact derivatives and the Gauss-Newton option (:mod:`nmsm.tools.mtp.derivatives`)."""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem
from nmsm.tools.mtp.derivatives import blockwise_derivatives


def _problem():
    p = OptimizationProblem("toy")
    x = p.variable("x", [0.3, -0.7, 1.1], -5.0, 5.0, scale=1.0)
    p.add_cost("curved", cs.vertcat(x[0] ** 2 - 1.0, x[0] * x[1], cs.sin(x[2])), weight=2.0)
    p.add_cost("plain", cs.vertcat(x[1] - x[2], x[2] ** 3))
    p.add_constraint("c", x[0] * x[1] + x[2] ** 2, -1.0, 1.0)
    return p


def _hess(p, **kw):
    f = blockwise_derivatives(p, **kw)["hess_lag"]
    x0 = np.array([0.4, -0.2, 0.9])
    h = np.array(f(x0, np.zeros(0), 1.0, np.array([0.5])).full())
    return x0, h + np.triu(h, 1).T


def test_exact_hessian_matches_casadi():
    p = _problem()
    x0, h = _hess(p)
    x = p.scaled_vector()
    lam = 0.5
    lag = p.objective() + lam * (p.constraints[0].expression)
    ref = np.array(cs.Function("h", [x], [cs.hessian(lag, x)[0]])(x0).full())
    assert np.allclose(h, ref, atol=1e-12)


def test_gauss_newton_replaces_only_the_named_cost():
    p = _problem()
    x0, h_gn = _hess(p, gauss_newton=("curved",))
    _, h_exact = _hess(p)
    x = p.scaled_vector()
    curved = p.costs[0]
    jac = np.array(cs.Function("j", [x], [cs.jacobian(curved.residuals, x)])(x0).full())
    exact_curved = np.array(cs.Function("h", [x], [cs.hessian(curved.weight * cs.sumsqr(curved.residuals), x)[0]])(x0).full())
    assert np.allclose(h_gn, h_exact - exact_curved + 2.0 * curved.weight * jac.T @ jac, atol=1e-12)
    assert not np.allclose(h_gn, h_exact)  # the curved residuals' second derivatives are dropped

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


def _problem_with_blocks():
    """Four constraint blocks of different sizes (one linear) and a curved objective."""
    p = OptimizationProblem("blocks")
    x = p.variable("x", [0.3, -0.7, 1.1, 0.2], -5.0, 5.0, scale=1.0)
    p.add_cost("curved", cs.vertcat(x[0] ** 2 - 1.0, x[0] * x[1], cs.sin(x[2]) * x[3]))
    p.add_constraint("a", cs.vertcat(x[0] * x[1], x[2] ** 2), -1.0, 1.0)
    p.add_constraint("b", x[1] + 2 * x[3], -1.0, 1.0)
    p.add_constraint("c", cs.vertcat(cs.exp(x[3]) * x[0], x[1] * x[2] * x[3], x[2]), -3.0, 3.0)
    p.add_constraint("d", cs.cos(x[0] + x[3]), -1.0, 1.0)
    return p


def _evaluate(p, threads):
    d = blockwise_derivatives(p, threads=threads)
    x0, lam = np.array([0.4, -0.2, 0.9, 0.7]), np.array([0.5, -1.5, 2.0, 0.25, -0.75, 1.25, 3.0])
    g, jac = (np.array(v.full()) for v in d["jac_g"](x0, np.zeros(0)))
    hess = np.array(d["hess_lag"](x0, np.zeros(0), 0.8, lam).full())
    return g, jac, hess


def test_parallel_groups_give_the_sequential_derivatives():
    p = _problem_with_blocks()
    g1, jac1, hess1 = _evaluate(p, 1)
    x = p.scaled_vector()
    jac_ref = np.array(cs.Function("j", [x], [cs.jacobian(p.constraint_vector()[0], x)])([0.4, -0.2, 0.9, 0.7]).full())
    assert np.allclose(jac1, jac_ref, atol=1e-14)
    for threads in (0, 2, 3, 8):  # 0: the plain sum; 8 > 5 parts: one group per part
        g, jac, hess = _evaluate(p, threads)
        assert np.array_equal(g, g1)
        assert np.allclose(jac, jac1, atol=1e-14) and np.allclose(hess, hess1, atol=1e-13), threads
        assert not np.allclose(hess, 0.0)

"""Block-wise exact derivatives for IPOPT (``jac_g`` and ``hess_lag`` nlpsol options).

CasADi's default Jacobian of the constraints and Hessian of the Lagrangian colour the
*whole* sparsity pattern at once, so one block that needs many colours (MTP's moment
rows, which touch every muscle of a frame) makes every block pay for them. Here each
constraint block and the objective get their own derivative (their own colouring, forward
or reverse), and the results are stacked / summed, optionally by groups of blocks on
parallel threads. Values are identical to the default (to rounding); only the cost changes.

Use: ``problem.solve("ipopt", casadi_options=blockwise_derivatives(problem))`` (MTP tasks:
:func:`nmsm.tools.mtp.problem.solve_task_problem`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as cs

from nmsm.core.problem import OptimizationProblem


def blockwise_derivatives(problem: OptimizationProblem, *, gauss_newton: Sequence[str] = (),
                          threads: int = 1) -> dict[str, Any]:
    """``{"jac_g": Function(x, p) -> (g, J), "hess_lag": Function(x, p, lam_f, lam_g) -> H}``.

    ``H`` is the upper triangle (``triu``) of the symmetric Hessian, as CasADi's own
    ``nlp_hess_l`` returns it. Cost terms named in ``gauss_newton`` contribute their
    Gauss-Newton matrix ``2 w J^T J`` (``J`` their exact residual Jacobian) instead of their
    exact Hessian; gradients and the solution's optimality are unchanged. (``nmsm run`` keeps
    the exact Hessian: with Gauss-Newton for the Synergy Extrapolation activation terms IPOPT
    stopped unconverged on a tutorial; docs/developing.md, "MTP: measurements".) With
    ``threads`` > 1 the blocks of ``J`` and ``H`` are dealt round-robin into that many groups
    evaluated on parallel threads
    (:func:`parallel_vertcat`, :func:`parallel_sum`).
    """
    x = problem.scaled_vector()
    p = problem.parameter_vector()
    g, _, _ = problem.constraint_vector()
    blocks = [c.expression for c in problem.constraints]
    n_g, n_x = g.numel(), x.numel()
    jacobians = [cs.jacobian(b, x) for b in blocks]
    jac = parallel_vertcat(jacobians, [x, p], threads) if blocks else cs.MX(0, n_x)
    jac_g = cs.Function("nlp_jac_g", [x, p], [g, jac], ["x", "p"], ["g", "jac_g_x"])
    lam_f = cs.MX.sym("lam_f")
    lam_g = cs.MX.sym("lam_g", n_g)
    parts = [cs.triu(lam_f * _objective_hessian(problem, x, set(gauss_newton)))]
    start = 0
    for b in blocks:
        n = b.numel()
        if n:
            parts.append(cs.triu(_hessian(cs.dot(lam_g[start : start + n], b), x)))
        start += n
    hess = parallel_sum(parts, [x, p, lam_f, lam_g], threads)
    hess_lag = cs.Function(
        "nlp_hess_l", [x, p, lam_f, lam_g], [hess], ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"]
    )
    return {"jac_g": jac_g, "hess_lag": hess_lag}


def parallel_sum(parts: Sequence[cs.MX], inputs: Sequence[cs.MX], threads: int) -> cs.MX:
    """``sum(parts)`` (MX of one shape, functions of ``inputs``), the parts dealt round-robin
    into ``threads`` groups evaluated in parallel (:func:`_in_parallel`); ``threads`` <= 1:
    the plain sum."""
    n_groups = max(1, min(threads, len(parts)))
    sums = [_sum(parts[k::n_groups], parts[0].shape) for k in range(n_groups)]
    return sums[0] if len(sums) == 1 else _in_parallel(sums, inputs)


def parallel_vertcat(blocks: Sequence[cs.MX], inputs: Sequence[cs.MX], threads: int) -> cs.MX:
    """``vertcat(blocks)`` (MX with one column count), the blocks dealt round-robin into
    ``threads`` groups evaluated in parallel: each group fills its blocks' rows of the
    whole matrix (zeros elsewhere) and the groups are summed; ``threads`` <= 1: the plain
    ``vertcat``."""
    n_groups = max(1, min(threads, len(blocks)))
    if n_groups == 1:
        return cs.vertcat(*blocks)
    groups = [
        cs.vertcat(*[b if i % n_groups == k else cs.MX(*b.shape) for i, b in enumerate(blocks)])
        for k in range(n_groups)
    ]
    return _in_parallel(groups, inputs)


def _sum(parts: Sequence[cs.MX], shape: tuple[int, int]) -> cs.MX:
    total = cs.MX(*shape)
    for part in parts:
        total = total + part
    return total


def _in_parallel(groups: Sequence[cs.MX], inputs: Sequence[cs.MX]) -> cs.MX:
    """``sum(groups)``, each group on its own thread: every group (on the union sparsity of
    all) is one case of a switch function, mapped over the groups with CasADi's ``thread``
    parallelization and summed by the map's output reduction. Groups are dealt
    deterministically, so a run's floating-point sums do not depend on timing."""
    union = groups[0].sparsity()
    for group in groups[1:]:
        union = union + group.sparsity()
    cases = [cs.Function(f"group_{k}", list(inputs), [cs.project(g, union)]) for k, g in enumerate(groups)]
    switch = cs.Function.conditional("groups", cases, cases[-1])
    mapped = switch.map("parallel_groups", "thread", len(cases), list(range(1, len(inputs) + 1)), [0])
    return mapped(cs.DM(range(len(cases))).T, *inputs)


def _objective_hessian(problem: OptimizationProblem, x: cs.MX, gauss_newton: set[str]) -> cs.MX:
    """Exact Hessian of the objective, Gauss-Newton for the costs named in ``gauss_newton``."""
    if not gauss_newton:
        return _hessian(problem.objective(), x)
    exact = cs.MX(0)
    approximated = cs.MX(x.numel(), x.numel())
    for c in problem.costs:
        if c.name in gauss_newton or getattr(c.term, "type", None) in gauss_newton:
            if c.residuals.numel() and cs.depends_on(c.residuals, x):
                jac = cs.jacobian(c.residuals, x)
                approximated = approximated + 2.0 * c.weight * cs.mtimes(jac.T, jac)
        else:
            exact = exact + c.weight * cs.sumsqr(c.residuals)
    return _hessian(exact, x) + approximated


def _hessian(expression: cs.MX, x: cs.MX) -> cs.MX:
    """Symmetric Hessian of a scalar MX expression (zero if it does not depend on ``x``)."""
    if not cs.depends_on(expression, x):
        return cs.MX(x.numel(), x.numel())
    h, _ = cs.hessian(expression, x)
    return h


def gauss_newton_hessian(problem: OptimizationProblem) -> dict[str, Any]:
    """``hess_lag`` with the Gauss-Newton objective Hessian ``2 lam_f J^T J`` (``J`` = residual Jacobian).

    For sum-of-squares objectives (MTLI): only first derivatives of the residuals are needed,
    so building and evaluating it is much cheaper than the exact Hessian; IPOPT still
    converges (the Gauss-Newton matrix is positive semi-definite). Constraint Hessians, if
    any, stay exact (block-wise).
    """
    x = problem.scaled_vector()
    p = problem.parameter_vector()
    g, _, _ = problem.constraint_vector()
    lam_f = cs.MX.sym("lam_f")
    lam_g = cs.MX.sym("lam_g", g.numel())
    jac = cs.jacobian(problem.residual_vector(), x)
    hess = 2 * lam_f * cs.mtimes(jac.T, jac)
    start = 0
    for c in problem.constraints:
        n = c.expression.numel()
        if n:
            hess = hess + _hessian(cs.dot(lam_g[start : start + n], c.expression), x)
        start += n
    hess_lag = cs.Function(
        "nlp_hess_l", [x, p, lam_f, lam_g], [cs.triu(hess)], ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"]
    )
    return {"hess_lag": hess_lag}

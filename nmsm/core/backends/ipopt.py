"""IPOPT back end: CasADi ``nlpsol`` with exact first and second derivatives.

pip's CasADi ships IPOPT with MUMPS only; a requested HSL solver (ma27/ma57/ma77/ma86/
ma97) falls back to MUMPS with a warning unless an HSL library is found.
"""

from __future__ import annotations

import ctypes.util
import time
import warnings
from typing import TYPE_CHECKING, Any, ClassVar

import casadi as cs
import numpy as np

from nmsm.core.backends.base import Backend
from nmsm.core.convergence import ConvergenceHistory
from nmsm.core.function_names import function_name
from nmsm.core.interrupts import SolveInterrupted, interrupt_after_solve
from nmsm.core.progress import SolveProgress, solve_progress
from nmsm.core.solution import Solution
from nmsm.core.threads import limit_solver_blas_threads

if TYPE_CHECKING:
    from nmsm.core.problem import OptimizationProblem

HSL_SOLVERS = {"ma27", "ma57", "ma77", "ma86", "ma97"}


def resolve_linear_solver(requested: str | None) -> str:
    """The linear solver IPOPT can actually use for ``requested`` (warns on fallback)."""
    name = (requested or "mumps").strip().lower()
    if name in HSL_SOLVERS:
        if ctypes.util.find_library("hsl") or ctypes.util.find_library("coinhsl"):
            return name
        warnings.warn(
            f"linear solver '{name}' needs the HSL library, which pip's CasADi does not ship; "
            "using 'mumps' instead",
            stacklevel=3,
        )
        return "mumps"
    if name != "mumps":
        warnings.warn(f"unknown IPOPT linear solver '{name}'; using 'mumps'", stacklevel=3)
        return "mumps"
    return name


def _sweeps(rows: np.ndarray, columns: np.ndarray, n_rows: int, n_columns: int) -> tuple[int, int]:
    """(forward, reverse) sweeps of a Jacobian with non-zeros at ``rows``, ``columns``: the
    colours of its columns and of its rows."""
    pattern = cs.Sparsity.triplet(n_rows, n_columns, rows.tolist(), columns.tolist())
    return pattern.uni_coloring().size2(), pattern.T.uni_coloring().size2()


def jacobian_direction_options(problem: OptimizationProblem) -> dict[str, Any]:
    """``nlpsol`` options that compute the constraint Jacobian, block by block of
    constraints, with the AD mode needing fewer sweeps for the block: reverse (one sweep per
    colour of its rows) unless its columns need fewer colours (then forward).

    CasADi's own choice, one mode for the whole Jacobian, leans to forward mode, which is
    slow for collocation problems whose per-point functions have many inputs and few
    outputs; and a block whose rows all share some columns (e.g. global design variables in
    every point's rows) needs as many reverse sweeps as rows. When every block takes the
    same mode, only CasADi's ``ad_weight`` is set; otherwise ``jac_g`` is a Function whose
    blocks are differentiated separately, each in its own mode."""
    g, _, _ = problem.constraint_vector()
    if g.numel() == 0:
        return {}
    x = problem.scaled_vector()
    rows, columns = (np.asarray(v, dtype=int) for v in cs.jacobian_sparsity(g, x).get_triplet())
    offsets = np.cumsum([0] + [c.expression.numel() for c in problem.constraints])
    reverse_blocks = []
    for start, end in zip(offsets[:-1], offsets[1:]):
        inside = (rows >= start) & (rows < end)
        forward, reverse = _sweeps(rows[inside] - start, columns[inside], end - start, x.numel())
        reverse_blocks.append(reverse <= forward)
    if all(reverse_blocks) or not any(reverse_blocks):
        return {"oracle_options": {"ad_weight": 1.0 if reverse_blocks[0] else 0.0}}
    parts, stacked = [], []
    for wanted in (True, False):
        chosen = [i for i, reverse in enumerate(reverse_blocks) if reverse == wanted]
        expression = cs.vertcat(*[problem.constraints[i].expression for i in chosen])
        parts.append(cs.jacobian(expression, x, {"helper_options": {"ad_weight": 1.0 if wanted else 0.0}}))
        stacked += [row for i in chosen for row in range(offsets[i], offsets[i + 1])]
    position = np.empty(len(stacked), dtype=int)
    position[stacked] = np.arange(len(stacked))
    jacobian = cs.vertcat(*parts)[position.tolist(), :]
    jac_g = cs.Function("nlp_jac_g", [x, problem.parameter_vector()], [g, jacobian], ["x", "p"], ["g", "jac_g_x"])
    return {"jac_g": jac_g}


def solve_ipopt(
    problem: OptimizationProblem,
    *,
    max_iter: int = 3000,
    tol: float = 1e-6,
    constr_viol_tol: float | None = None,
    acceptable_tol: float | None = None,
    linear_solver: str | None = "mumps",
    hessian: str = "exact",
    print_level: int = 5,
    print_time: bool = False,
    ipopt_options: dict[str, Any] | None = None,
    casadi_options: dict[str, Any] | None = None,
    initial_guess: np.ndarray | None = None,
) -> Solution:
    """Solve ``problem`` with IPOPT; ``hessian`` is 'exact' or 'limited-memory'."""
    if hessian not in ("exact", "limited-memory"):
        raise ValueError(f"hessian must be 'exact' or 'limited-memory', got '{hessian}'")
    problem.require_no_lifted_parameters("ipopt")
    xs = problem.scaled_vector()
    ps = problem.parameter_vector()
    g, lbg, ubg = problem.constraint_vector()
    nlp = {"x": xs, "p": ps, "f": problem.objective(), "g": g}
    opts: dict[str, Any] = {
        "ipopt.max_iter": int(max_iter),
        "ipopt.tol": float(tol),
        "ipopt.linear_solver": resolve_linear_solver(linear_solver),
        "ipopt.hessian_approximation": hessian,
        "ipopt.print_level": int(print_level),
        "ipopt.sb": "yes",
        "print_time": print_time,
    }
    if constr_viol_tol is not None:
        opts["ipopt.constr_viol_tol"] = float(constr_viol_tol)
    if acceptable_tol is not None:
        opts["ipopt.acceptable_tol"] = float(acceptable_tol)
    for key, value in (ipopt_options or {}).items():
        opts[f"ipopt.{key}"] = value
    progress = solve_progress(problem.name) if int(print_level) == 0 else None
    callback = _IterateCallback(progress, xs.numel(), g.numel(), ps.numel(), lbg, ubg)
    opts["iteration_callback"] = callback  # progress lines when IPOPT is silent; the last iterate for a stop
    opts.update(casadi_options or {})
    solver = cs.nlpsol(function_name(problem.name or "nlp"), "ipopt", nlp, opts)
    limit_solver_blas_threads()
    lo, hi = problem.bounds_scaled()
    x0 = problem.initial_scaled() if initial_guess is None else np.asarray(initial_guess, dtype=float)
    x0 = np.clip(x0, lo, hi)
    start = time.perf_counter()
    stop: KeyboardInterrupt | None = None
    try:
        with interrupt_after_solve():  # Ctrl-C: KeyboardInterrupt, not an unconverged "result"
            result = solver(x0=x0, p=problem.parameter_values(), lbx=lo, ubx=hi, lbg=lbg, ubg=ubg)
    except KeyboardInterrupt as exc:
        if callback.x is None:
            raise
        stop = exc
    wall = time.perf_counter() - start
    stats = solver.stats()
    if stop is not None:  # the last iterate IPOPT reported, not what it returned on the way out
        x_opt = callback.x
        cost = float(np.asarray(problem.evaluate(problem.objective(), x_opt)).ravel()[0])
        success, status = False, "Stopped_By_SIGINT"
    else:
        x_opt = np.asarray(result["x"].full()).ravel()
        cost = float(result["f"])
        success, status = bool(stats.get("success", False)), str(stats.get("return_status", "unknown"))
    solution = Solution(
        values=problem.unpack(x_opt),
        cost=cost,
        term_costs=problem.term_costs(x_opt),
        success=success,
        status=status,
        iterations=int(stats.get("iter_count", callback.iterations)) if stop is None else callback.iterations,
        wall_time=wall,
        backend="ipopt",
        x_scaled=x_opt,
        constraints=problem.constraint_report(x_opt),
        history=ConvergenceHistory.from_ipopt_stats(stats),
    )
    if stop is not None:
        raise SolveInterrupted(str(stop) or "stopped by SIGINT during the solve", solution) from stop
    return solution


class IpoptBackend(Backend):
    """IPOPT through CasADi ``nlpsol`` (:func:`solve_ipopt`): costs, constraints and bounds of an
    :class:`~nmsm.core.problem.OptimizationProblem`, exact first and second derivatives."""

    type: ClassVar[str] = "ipopt"

    def solve(self, problem: OptimizationProblem, **options: Any) -> Solution:
        return solve_ipopt(problem, **options)


class _IterateCallback(cs.Callback):
    """CasADi ``iteration_callback``: keeps each IPOPT iterate (scaled ``x``, :attr:`x`;
    :attr:`iterations` is the last one's number) and, given a
    :class:`~nmsm.core.progress.SolveProgress`, reports its cost and largest constraint
    violation there."""

    def __init__(self, progress: SolveProgress | None, nx: int, ng: int, n_p: int, lbg: np.ndarray,
                 ubg: np.ndarray) -> None:
        cs.Callback.__init__(self)
        self.progress = progress
        self.x: np.ndarray | None = None
        self.iterations = -1  # the first call reports iteration 0
        self.sizes = {"x": nx, "f": 1, "g": ng, "lam_x": nx, "lam_g": ng, "lam_p": n_p}
        self.lbg = np.asarray(lbg, dtype=float).ravel()
        self.ubg = np.asarray(ubg, dtype=float).ravel()
        self.construct("nmsm_progress", {})

    def get_n_in(self) -> int:
        return cs.nlpsol_n_out()

    def get_n_out(self) -> int:
        return 1

    def get_name_in(self, i: int) -> str:
        return cs.nlpsol_out(i)

    def get_name_out(self, i: int) -> str:
        return "ret"

    def get_sparsity_in(self, i: int) -> cs.Sparsity:
        return cs.Sparsity.dense(self.sizes[cs.nlpsol_out(i)], 1)

    def eval(self, arg: list[cs.DM]) -> list[int]:
        self.x = np.asarray(arg[cs.nlpsol_out().index("x")]).ravel().copy()
        self.iterations += 1
        if self.progress is not None and self.progress.tick():
            f = float(arg[cs.nlpsol_out().index("f")])
            g = np.asarray(arg[cs.nlpsol_out().index("g")]).ravel()
            violation = float(np.max(np.maximum(np.maximum(self.lbg - g, g - self.ubg), 0.0))) if g.size else None
            self.progress.report(f, violation)
        return [0]

"""IPOPT back end: CasADi ``nlpsol`` with exact first and second derivatives.

pip's CasADi ships IPOPT with MUMPS only; a requested HSL solver (ma27/ma57/ma77/ma86/
ma97) falls back to MUMPS with a warning unless an HSL library is found.
"""

from __future__ import annotations

import ctypes.util
import time
import warnings
from typing import TYPE_CHECKING, Any

import casadi as cs
import numpy as np

from nmsm.core.interrupts import interrupt_after_solve
from nmsm.core.problem import Solution

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
    opts.update(casadi_options or {})
    solver = cs.nlpsol(problem.name.replace(" ", "_") or "nlp", "ipopt", nlp, opts)
    lo, hi = problem.bounds_scaled()
    x0 = problem.initial_scaled() if initial_guess is None else np.asarray(initial_guess, dtype=float)
    x0 = np.clip(x0, lo, hi)
    start = time.perf_counter()
    with interrupt_after_solve():  # Ctrl-C: KeyboardInterrupt, not an unconverged "result"
        result = solver(x0=x0, p=problem.parameter_values(), lbx=lo, ubx=hi, lbg=lbg, ubg=ubg)
    wall = time.perf_counter() - start
    stats = solver.stats()
    x_opt = np.asarray(result["x"].full()).ravel()
    term_costs = problem.term_costs(x_opt)
    return Solution(
        values=problem.unpack(x_opt),
        cost=float(result["f"]),
        term_costs=term_costs,
        success=bool(stats.get("success", False)),
        status=str(stats.get("return_status", "unknown")),
        iterations=int(stats.get("iter_count", -1)),
        wall_time=wall,
        backend="ipopt",
        x_scaled=x_opt,
        constraints=problem.constraint_report(x_opt),
    )

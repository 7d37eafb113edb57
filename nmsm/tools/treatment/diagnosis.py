"""Convergence summary of a treatment solve: cost per term, active and violated constraints.

Constraint blocks are the problem's: the collocation defects (equalities) and one block
per constraint term. For each block: the largest violation of its bounds (in the term's
scaled units: ``(value - mid)/(max_error - min_error)`` against ``[-0.5, 0.5]``), how many
rows sit on a bound (active, within 1e-5 of the scaled range) and where the term was
declared (settings file and line).
"""

from __future__ import annotations

import attrs
import numpy as np

from nmsm.core.problem import Solution
from nmsm.tools.treatment.formulation import TreatmentProblem


def convergence_summary(built: TreatmentProblem, solution: Solution, *, tol: float = 1e-5) -> str:
    """Human-readable report (text)."""
    lines = [
        f"{built.problem.name}: IPOPT {solution.status} after {solution.iterations} iterations, "
        f"{solution.wall_time:.2f} s; objective {solution.cost:.8g}",
        "",
        "cost terms (weighted contribution):",
    ]
    for name, value in solution.term_costs.items():
        lines.append(f"  {name:<56s} {value:.6g}")
    report = built.problem.constraint_report(solution.x_scaled, tol)
    lines += ["", "constraints:"]
    for status, entry in zip(report, built.problem.constraints):
        equality = bool(np.all(entry.lower == entry.upper))
        where = f" ({status.source.file}:{status.source.line})" if status.source and status.source.file else ""
        flag = "VIOLATED" if status.max_violation > 1e-4 else ("violated" if status.max_violation > 1e-6 else "ok")
        if equality:
            detail = f"equality, {status.size} rows, max |residual| {status.max_violation:.3g}"
        else:
            detail = f"{status.size} rows, {status.n_active} active at a bound, max violation {status.max_violation:.3g}"
        lines.append(f"  [{flag:8s}] {status.name:<48s} {detail}{where}")
    violated = [s for s in report if s.max_violation > 1e-4]
    lines += ["", f"{len(violated)} constraint block(s) violated by more than 1e-4" if violated
              else "all constraints satisfied within 1e-4"]
    return "\n".join(lines)


#: largest constraint violation of a starting point (in each block's scaled units, as in
#: :func:`convergence_summary`) above which it is reported as far from dynamic consistency
FAR_FROM_CONSISTENT = 1e2


@attrs.frozen
class WorstConstraint:
    """The largest violation of a point: the block, its size (scaled units) and where."""

    block: str
    violation: float
    where: str

    def message(self) -> str:
        return (f"the initial guess violates the constraint block '{self.block}' by {self.violation:.3g} (scaled "
                f"units: collocation defects per state scale, path constraints per (max_error - min_error)), "
                f"worst at {self.where}")


def worst_constraint(built: TreatmentProblem, x_scaled: np.ndarray) -> WorstConstraint | None:
    """The constraint row of the problem violated most at ``x_scaled``: its block, and the
    state or column and collocation point (with its time) it belongs to; None without
    constraints."""
    problem = built.problem
    if not problem.constraints:
        return None
    values = problem.function([c.expression for c in problem.constraints], "constraints").call(
        [x_scaled, problem.parameter_values()])
    best: tuple[float, int, int] | None = None
    for b, (entry, v) in enumerate(zip(problem.constraints, values)):
        g = np.asarray(v.full()).ravel()
        violation = np.maximum(entry.lower - g, 0) + np.maximum(g - entry.upper, 0)
        violation = np.where(np.isfinite(violation), violation, np.inf)
        if violation.size and (best is None or violation.max() > best[0]):
            best = (float(violation.max()), b, int(np.argmax(violation)))
    if best is None:
        return None
    violation, b, row = best
    entry = problem.constraints[b]
    mesh = built.trajectory.phase.mesh
    K = mesh.n_collocation
    times = mesh.times("collocation") * built.data.final_time_guess
    size = entry.expression.numel()
    if entry.name.endswith("dynamics_defects"):
        state = built.trajectory.phase.states.names[row // K]
        point = row % K
        where = f"state '{state}', collocation point {point + 1} of {K} (t = {times[point]:.4g} s)"
    elif size % K == 0 and size >= K:
        point, column = row % K, row // K
        where = (f"collocation point {point + 1} of {K} (t = {times[point]:.4g} s)"
                 + (f", column {column + 1} of {size // K}" if size > K else ""))
    else:
        where = f"row {row + 1} of {size}"
    return WorstConstraint(entry.name, violation, where)

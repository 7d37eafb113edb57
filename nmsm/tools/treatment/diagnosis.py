"""Convergence summary of a treatment solve: cost per term, active and violated constraints.

Constraint blocks are the problem's: the collocation defects (equalities) and one block
per constraint term. For each block: the largest violation of its bounds (in the term's
scaled units: ``(value - mid)/(max_error - min_error)`` against ``[-0.5, 0.5]``), how many
rows sit on a bound (active, within 1e-5 of the scaled range) and where the term was
declared (settings file and line).
"""

from __future__ import annotations

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

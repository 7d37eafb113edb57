"""Score another solution (e.g. the original MATLAB pipeline's) in our problem, and compare.

:func:`score_solution` builds the problem of a settings file and evaluates it - cost per
term, constraint violations - at the solution stored in a results folder (its
``<trial>_states.sto``, ``_accelerations.sto``, controls, synergy weights), without
solving. References (tracked data, initial controls) stay those of the settings file.

:func:`tracking_rms` gives, per tracking term, the RMS over the collocation points of its
raw quantity (e.g. q_exp - q in rad, τ_exp - τ in N·m).
"""

from __future__ import annotations

import os
from typing import Any

import attrs
import numpy as np

from nmsm.tools.treatment.run import TreatmentRun, run_settings


def score_solution(settings_file: str | os.PathLike[str], solution_directory: str | os.PathLike[str],
                   **options: Any) -> TreatmentRun:
    """Evaluate ``settings_file``'s problem at the solution in ``solution_directory``."""
    return run_settings(settings_file, guess_directory=solution_directory, evaluate_only=True, **options)


def tracking_rms(run: TreatmentRun) -> dict[str, float]:
    """RMS (over collocation points) of each ``*_tracking`` term's raw quantity."""
    ctx = run.prepared.built.context
    out = {}
    for term in run.prepared.terms:
        if term.type.endswith("_tracking") and not getattr(term, "discrete", False):
            values = run.result.value(term.quantity(ctx))
            out[term.label] = float(np.sqrt(np.mean(values**2)))
    return out


def max_constraint_violation(run: TreatmentRun) -> dict[str, float]:
    """Worst violation per constraint block (scaled units, see diagnosis) above 1e-6."""
    return {c.name: c.max_violation for c in run.solution.constraints if c.max_violation > 1e-6}


@attrs.frozen
class Comparison:
    """Our run against another solution scored in our problem."""

    ours: TreatmentRun
    theirs: TreatmentRun

    @property
    def cost_ratio(self) -> float:
        return self.ours.cost / self.theirs.initial_cost if self.theirs.initial_cost > 0 else float("inf")

    def rms(self) -> dict[str, tuple[float, float]]:
        a, b = tracking_rms(self.ours), tracking_rms(self.theirs)
        return {k: (a[k], b.get(k, float("nan"))) for k in a}

    def report(self) -> str:
        lines = [
            f"ours: {self.ours.solution.status}, {self.ours.solution.iterations} iterations, "
            f"{self.ours.solution.wall_time:.1f} s, cost {self.ours.cost:.6g}",
            f"theirs scored in our problem: cost {self.theirs.initial_cost:.6g} (ratio ours/theirs {self.cost_ratio:.3f})",
        ]
        violations = max_constraint_violation(self.theirs)
        if violations:
            lines.append("  theirs violates: " + ", ".join(f"{k} {v:.3g}" for k, v in violations.items()))
        for label, (a, b) in self.rms().items():
            lines.append(f"  RMS {label:<56s} ours {a:.4g}  theirs {b:.4g}")
        return "\n".join(lines)

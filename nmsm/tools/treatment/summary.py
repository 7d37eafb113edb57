"""The console summary of a Tracking, Verification or Design Optimization run.

IPOPT's outcome and the objective; per group of tracking terms (one group per term type)
the term whose RMS error over the collocation points is largest against its
``max_allowable_error``, that RMS in the term's unit and as a multiple of its
``max_allowable_error``, and how many terms of the group are above theirs; the largest
constraint violation; for Design Optimization the change of each design
goal (every cost term that tracks nothing) from the initial guess to the solution.
"""

from __future__ import annotations

from collections.abc import Mapping

import attrs
import numpy as np

from nmsm.core.ocp import evaluation_of
from nmsm.tools.treatment.outcome import TreatmentRun

#: term type -> (factor for rotational coordinates, unit for rotational, factor otherwise, unit otherwise)
UNITS: dict[str, tuple[float, str, float, str]] = {
    "generalized_coordinate_tracking": (float(np.degrees(1.0)), "deg", 1000.0, "mm"),
    "generalized_speed_tracking": (float(np.degrees(1.0)), "deg/s", 1.0, "m/s"),
    "generalized_acceleration_tracking": (float(np.degrees(1.0)), "deg/s²", 1.0, "m/s²"),
    "inverse_dynamics_load_tracking": (1.0, "N·m", 1.0, "N"),
    "external_force_tracking": (1.0, "N", 1.0, "N"),
    "external_moment_tracking": (1.0, "N·m", 1.0, "N·m"),
    "marker_position_tracking": (1000.0, "mm", 1000.0, "mm"),
    "center_of_pressure_tracking": (1000.0, "mm", 1000.0, "mm"),
    "muscle_activation_tracking": (1.0, "", 1.0, ""),
}
#: constraint violation above which a block is reported as violated (scaled units)
VIOLATION = 1e-4


def _scale(run: TreatmentRun, term_type: str, label: str) -> tuple[float, str]:
    """Factor from the term's raw quantity (SI, rad) to the shown unit, and the unit."""
    from nmsm.io.storage import strip_load_suffix

    factor_r, unit_r, factor, unit = UNITS.get(term_type, (1.0, "", 1.0, ""))
    name = label.split(":")[1] if ":" in label else ""
    model = run.prepared.model
    if term_type == "controller_tracking":  # a torque control (N·m or N) or a muscle or synergy control (-)
        coordinate = strip_load_suffix(name)
        if coordinate in model.coordinate_names:
            return 1.0, "N·m" if model.is_rotational(coordinate) else "N"
        return 1.0, ""
    if name in model.coordinate_names:
        return (factor_r, unit_r) if model.is_rotational(name) else (factor, unit)
    return factor_r, unit_r


@attrs.frozen
class TrackingGroup:
    """The tracking terms of one type: how many, how many end above their
    ``max_allowable_error``, and the one whose RMS error is the largest multiple of its
    ``max_allowable_error`` (that RMS in ``unit``, and the multiple)."""

    count: int
    above: int
    worst_rms: float
    worst_ratio: float
    unit: str
    worst_label: str


def tracking_rms(run: TreatmentRun) -> dict[str, float]:
    """Term label -> RMS over the collocation points of the term's error, its raw quantity
    minus its ``error_center`` (e.g. q_exp - q in rad, τ_exp - τ in N·m), for every
    ``*_tracking`` term of the run that is evaluated over time."""
    ctx = run.prepared.built.context
    out = {}
    for term in run.prepared.terms:
        if term.type.endswith("_tracking") and evaluation_of(term) != "discrete":
            values = np.asarray(run.result.value(term.quantity(ctx)), dtype=float) - float(term.error_center)
            out[term.label] = float(np.sqrt(np.mean(values**2)))
    return out


def tracking_groups(run: TreatmentRun) -> dict[str, TrackingGroup]:
    """Term type -> :class:`TrackingGroup` of the terms of :func:`tracking_rms`."""
    rms = tracking_rms(run)
    out: dict[str, TrackingGroup] = {}
    for term in run.prepared.terms:
        if term.label not in rms:
            continue
        ratio = rms[term.label] / float(term.max_allowable_error)
        group = out.get(term.type, TrackingGroup(0, 0, float("nan"), -1.0, "", ""))
        if ratio > group.worst_ratio:
            factor, unit = _scale(run, term.type, term.label)
            group = attrs.evolve(group, worst_rms=factor * rms[term.label], worst_ratio=ratio, unit=unit,
                                 worst_label=term.label)
        out[term.type] = attrs.evolve(group, count=group.count + 1, above=group.above + int(ratio > 1.0))
    return out


def design_goal_changes(run: TreatmentRun, initial_costs: Mapping[str, float]) -> dict[str, tuple[float, float]]:
    """Cost entry -> (at the initial guess, at the solution) of each design goal: the cost
    terms of a Design Optimization that track nothing."""
    from nmsm.core.term import CostTerm

    if run.prepared.tool != "DO":
        return {}
    goals = {t.label for t in run.prepared.terms if isinstance(t, CostTerm) and not t.type.endswith("_tracking")}
    return {name: (float(initial_costs[name]), float(value)) for name, value in run.solution.term_costs.items()
            if name in initial_costs and name.split("#")[0] in goals}


def summary_lines(run: TreatmentRun, initial_costs: Mapping[str, float]) -> list[str]:
    """The console summary (module docstring); ``initial_costs`` are the cost terms at the
    initial guess."""
    solution = run.solution
    lines = [f"IPOPT {solution.status} after {solution.iterations} iterations, {solution.wall_time:.1f} s; "
             f"objective {run.initial_cost:.6g} -> {solution.cost:.6g}"]
    groups = tracking_groups(run)
    if groups:
        lines.append("tracking RMS (of each group the term furthest from its max_allowable_error):")
        for kind, g in groups.items():
            lines.append(f"  {kind:<36s} {g.worst_rms:10.4g} {g.unit:<6s} ({g.worst_ratio:.2g} x max_allowable_error; "
                         f"{g.worst_label}; {g.above} of {g.count} term(s) above theirs)")
    violations = [c for c in solution.constraints if np.isfinite(c.max_violation)]
    if violations:
        worst = max(violations, key=lambda c: c.max_violation)
        bad = sum(c.max_violation > VIOLATION for c in violations)
        lines.append(f"constraint violation: largest {worst.max_violation:.2g} ({worst.name}); {bad} of "
                     f"{len(violations)} block(s) above {VIOLATION:g}")
    for name, (before, after) in design_goal_changes(run, initial_costs).items():
        change = f"{100 * (after - before) / abs(before):+.1f} %" if before else "n/a"
        lines.append(f"design goal {name}: {before:.6g} -> {after:.6g} ({change})")
    return lines

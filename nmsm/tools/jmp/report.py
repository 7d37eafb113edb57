"""The JMP report: marker distance errors before and after, per task and per joint, and the
parameter changes.

Layout (one block per task, as Table 1 of the NMSM Pipeline JMP paper: rows are the task's
markers all together, then the markers of each personalized joint's two bodies, then each
marker; columns RMS and maximum distance error before and after, mm)::

    Task 1 'Right Knee': RightKnee_markers.trc, 0-1.64 s, 165 frames, 6 markers
    group                                    n   RMS before  RMS after   max before  max after
    all markers                              6        5.123      2.345       12.345      6.789
    joint knee_r (femur_r, tibia_r)          6        ...

Errors are the distances between model and experimental markers after inverse kinematics
with the model before and after the task (gaps excluded).
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.model.components import Model
from nmsm.tools.jmp.design import DesignVariable


@attrs.frozen
class ErrorRow:
    """Marker distance errors of a group of markers (m): RMS and max, before and after."""

    group: str
    markers: tuple[str, ...]
    rms_before: float
    rms_after: float
    max_before: float
    max_after: float


def _rms(errors: np.ndarray) -> float:
    e = errors[np.isfinite(errors)]
    return float(np.sqrt(np.mean(e**2))) if e.size else float("nan")


def _max(errors: np.ndarray) -> float:
    e = errors[np.isfinite(errors)]
    return float(e.max()) if e.size else float("nan")


def error_rows(model: Model, joints: Sequence[str], markers: Sequence[str], before: np.ndarray,
               after: np.ndarray) -> list[ErrorRow]:
    """Rows for all markers, each joint (markers on its parent and child bodies) and each marker.

    ``before``/``after``: ``(F, M)`` distances (m), columns in ``markers`` order.
    """
    rows = [ErrorRow("all markers", tuple(markers), _rms(before), _rms(after), _max(before), _max(after))]
    body_of = {m: model.marker(m).body for m in markers}
    for name in joints:
        joint = model.joint(name)
        bodies = (joint.parent_body, joint.child_body)
        chosen = [k for k, m in enumerate(markers) if body_of[m] in bodies]
        if not chosen:
            continue
        rows.append(ErrorRow(f"joint {name} ({', '.join(bodies)})", tuple(markers[k] for k in chosen),
                             _rms(before[:, chosen]), _rms(after[:, chosen]), _max(before[:, chosen]),
                             _max(after[:, chosen])))
    for k, m in enumerate(markers):
        rows.append(ErrorRow(f"marker {m}", (m,), _rms(before[:, k]), _rms(after[:, k]), _max(before[:, k]),
                             _max(after[:, k])))
    return rows


def _change(variable: DesignVariable, initial: float, final: float) -> str:
    delta = final - initial
    if variable.kind == "orientation":
        return f"{np.degrees(delta):+.3f} deg"
    if variable.kind == "scale":
        return f"{100 * delta:+.3f} %"
    return f"{1000 * delta:+.3f} mm"


def format_task(title: str, rows: Sequence[ErrorRow], variables: Sequence[DesignVariable], initial: np.ndarray,
                final: np.ndarray, solver: dict[str, Any], notes: Sequence[str] = ()) -> str:
    """The text block of one task."""
    lines = [title, "", "Marker distance error (mm)",
             f"  {'group':<48s} {'n':>3s} {'RMS before':>11s} {'RMS after':>10s} {'max before':>11s} {'max after':>10s}"]
    for row in rows:
        lines.append(f"  {row.group:<48s} {len(row.markers):>3d} {1000 * row.rms_before:>11.3f} "
                     f"{1000 * row.rms_after:>10.3f} {1000 * row.max_before:>11.3f} {1000 * row.max_after:>10.3f}")
    lines += ["", "Parameters (m, rad; scale factors relative to the task's input model)",
              f"  {'parameter':<48s} {'initial':>12s} {'final':>12s} {'change':>14s} {'bounds':>27s}"]
    any_at_bound = False
    for variable, a, b in zip(variables, initial, final):
        at_bound = bool(np.isclose(b, variable.lower, atol=1e-9) or np.isclose(b, variable.upper, atol=1e-9))
        any_at_bound |= at_bound
        lines.append(f"  {variable.label:<48s} {a:>12.6f} {b:>12.6f} {_change(variable, a, b):>14s} "
                     f"[{variable.lower:>11.5g}, {variable.upper:>11.5g}]{' *' if at_bound else ''}")
    lines += ["  (* at a bound)"] if any_at_bound else []
    lines += ["",
              f"Solver: {solver['status']}; {solver['iterations']} iterations, {solver['evaluations']} evaluations, "
              f"{solver['wall_time']:.2f} s; cost {solver['initial_cost']:.6g} -> {solver['cost']:.6g}"
              + (f"; {solver['reseated_frames']} frame(s) re-seated in their inverse kinematics"
                 if solver.get("reseated_frames") else "")]
    lines += [f"Note: {n}" for n in notes]
    return "\n".join(lines) + "\n"


def rows_to_json(rows: Sequence[ErrorRow]) -> list[dict[str, Any]]:
    return [attrs.asdict(r) | {"markers": list(r.markers)} for r in rows]


def write_json(path: Path, data: dict[str, Any]) -> None:
    def default(value: Any) -> Any:
        if isinstance(value, np.ndarray):
            return value.tolist()
        if isinstance(value, (np.floating, np.integer)):
            return value.item()
        if isinstance(value, Path):
            return str(value)
        raise TypeError(f"cannot write {type(value).__name__} to JSON")

    path.write_text(json.dumps(data, indent=2, default=default, allow_nan=True) + "\n", encoding="utf-8")

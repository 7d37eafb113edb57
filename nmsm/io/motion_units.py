"""Plausibility of a motion file's angle unit (its ``inDegrees`` header) against a model.

A motion (IK) file says its unit in the header (``inDegrees=yes``; no line or ``no``:
radians); readers convert the model's rotational coordinates with it
(:meth:`nmsm.io.storage.Table.to_radians`). A wrong header is not an error anyone sees:
degrees read as radians give joint angles of tens of radians, radians read as degrees give a
body that barely moves. :func:`warn_implausible_angles` warns, naming the file, the column,
its range in radians and degrees and the header, when

* a rotational column, in radians after the header's conversion, leaves [-2π, 2π], or lies
  more than π beyond the model's range of the coordinate (when the model gives one); or
* the header says degrees, every rotational column as written lies within [-π, π] and one
  of them spans at least :data:`SMALL_MOTION_SPAN` (as written): numbers that look like
  radians (as degrees, the whole motion would stay within ±3.1°).

It is used where motion files are read for a model: preprocessing's IK split, GCP's motion,
JMP / IK coordinate-task files, treatment optimization's tracked and guess motions, surrogate
creation's reference motion (``nmsm surrogate --motion``) and data-folder ``IKData`` files,
and every motion matched to a model's coordinates by
:func:`nmsm.model.id_tool.check_motion_columns` (``nmsm id``, ``markers``, ``muscle-analysis``).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Collection, Mapping
from pathlib import Path

import numpy as np

from nmsm.io.storage import Table

#: radians beyond a model coordinate's range that count as "far outside" it
FAR_BEYOND_RANGE = math.pi
#: span (as written) of the largest-moving rotational column above which degrees that never
#: leave [-π, π] look like radians
SMALL_MOTION_SPAN = 0.5
#: columns named in one warning
MAX_COLUMNS_NAMED = 3

Rotational = Collection[str] | Mapping[str, tuple[float, float] | None]


def _header(table: Table) -> str:
    if "inDegrees" in table.metadata:
        return f"inDegrees={table.metadata['inDegrees'].strip()}"
    if table.source is not None and not table.in_degrees:
        return "no inDegrees line (radians)"
    return f"inDegrees={'yes' if table.in_degrees else 'no'}"


def _span(values: np.ndarray, in_degrees: bool) -> str:
    """``a..b rad (c..d deg)`` of a column in the file's unit read with the header."""
    rad = np.deg2rad(values) if in_degrees else values
    return (f"{rad.min():.4g}..{rad.max():.4g} rad ({np.rad2deg(rad.min()):.4g}..{np.rad2deg(rad.max()):.4g} deg)")


def _range_of(rotational: Rotational, label: str) -> tuple[float, float] | None:
    if not isinstance(rotational, Mapping):
        return None
    bounds = rotational.get(label)
    if bounds is None:
        return None
    lo, hi = float(bounds[0]), float(bounds[1])
    return (lo, hi) if math.isfinite(lo) and math.isfinite(hi) and hi > lo else None


def implausible_angle_message(table: Table, rotational: Rotational, *, file: str | Path | None = None) -> str | None:
    """The warning text of :func:`warn_implausible_angles`, or None when the unit looks right.

    ``table``: the motion as read (the file's numbers, ``in_degrees`` from its header);
    ``rotational``: the model's rotational coordinate names, or a mapping name -> range
    ``(min, max)`` in rad (None: no range).
    """
    where = file if file is not None else table.source
    columns = [(j, label) for j, label in enumerate(table.labels) if label in rotational]
    if not columns or table.n_rows == 0:
        return None
    header = _header(table)
    too_large = []
    for j, label in columns:
        raw = table.data[:, j]
        rad = np.deg2rad(raw) if table.in_degrees else raw
        bounds = _range_of(rotational, label)
        reason = None
        if np.abs(rad).max() > 2 * math.pi:
            reason = "outside [-2π, 2π] rad"
        elif bounds is not None and (rad.min() < bounds[0] - FAR_BEYOND_RANGE
                                     or rad.max() > bounds[1] + FAR_BEYOND_RANGE):
            reason = f"far outside the model's range {bounds[0]:.4g}..{bounds[1]:.4g} rad"
        if reason:
            too_large.append(f"'{label}' {_span(raw, table.in_degrees)}, {reason}")
    if too_large:
        named = "; ".join(too_large[:MAX_COLUMNS_NAMED])
        more = f" (and {len(too_large) - MAX_COLUMNS_NAMED} more)" if len(too_large) > MAX_COLUMNS_NAMED else ""
        hint = ("the numbers look like degrees: the header may be wrong (inDegrees=yes)" if not table.in_degrees
                else "the header may be wrong, or the coordinates are not what the model's are")
        return f"{where}: read with {header}, rotational column(s) {named}{more}: {hint}"
    if table.in_degrees:
        raw = table.data[:, [j for j, _ in columns]]
        spans = np.ptp(raw, axis=0)
        if np.abs(raw).max() <= math.pi and spans.max() >= SMALL_MOTION_SPAN:
            k = int(np.argmax(spans))
            j, label = columns[k]
            column = table.data[:, j]
            return (f"{where}: {header}, but every rotational column as written lies within [-π, π]; the "
                    f"largest-moving, '{label}', is {column.min():.4g}..{column.max():.4g} as written, read as "
                    f"{_span(column, True)}; as radians it would be {_span(column, False)}: the numbers look like "
                    "radians, the header may be wrong (inDegrees=no)")
    return None


def warn_implausible_angles(table: Table, rotational: Rotational, *, file: str | Path | None = None,
                            stacklevel: int = 3) -> None:
    """``UserWarning`` when the motion's angle unit looks wrong (module docstring)."""
    message = implausible_angle_message(table, rotational, file=file)
    if message:
        warnings.warn(message, stacklevel=stacklevel)


__all__ = ["implausible_angle_message", "warn_implausible_angles"]

"""Error table of a GCP result, in the layout of Table 4 of the GCP paper (Jackson et al.,
2016): RMS errors, over a foot's time window, of the modeled against the experimental
ground reaction forces (N) and moments (N m, about the midfoot-superior point on the
floor), the foot translations (mm), rotations (deg; toe angle and the three hindfoot
angles) and foot-marker distances (mm).

:func:`rms_errors` computes one column; :func:`format_error_table` lays out several
columns (e.g. ``{"nmsm": ..., "original": ...}``) and, for exactly two, their ratio.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.values import FootValues, as_array

#: row labels in table order
ROWS = ("Fx (N)", "Fy (N)", "Fz (N)", "Mx (N m)", "My (N m)", "Mz (N m)", "translation (mm)", "rotation (deg)",
        "marker distance (mm)")


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def rms_errors(foot: FootInputs, values: FootValues) -> dict[str, float]:
    """One foot's RMS errors by :data:`ROWS` label (numeric ``values``)."""
    forces = as_array(values.forces) - as_array(values.experimental_forces)
    moments = as_array(values.moments) - as_array(values.experimental_moments)
    q_error = as_array(values.coordinates) - foot.coordinates.T
    markers = as_array(values.markers).T.reshape(foot.n_frames, 5, 3) - foot.markers
    out = {ROWS[k]: _rms(forces[k]) for k in range(3)}
    out.update({ROWS[3 + k]: _rms(moments[k]) for k in range(3)})
    out[ROWS[6]] = 1000.0 * _rms(q_error[4:7])
    out[ROWS[7]] = float(np.degrees(_rms(q_error[0:4])))
    out[ROWS[8]] = 1000.0 * _rms(np.linalg.norm(markers, axis=2))
    return out


def format_error_table(columns: Mapping[str, Mapping[str, float]], title: str = "GCP RMS errors") -> str:
    """Plain-text table: one row per :data:`ROWS` label, one column per entry of ``columns``
    (plus ``ratio`` = first / second when there are two)."""
    names = list(columns)
    header = f"{'':<22s}" + "".join(f"{n:>14s}" for n in names)
    ratio = len(names) == 2
    if ratio:
        header += f"{'ratio':>10s}"
    lines = [title, header]
    for row in ROWS:
        values = [columns[n].get(row, float("nan")) for n in names]
        line = f"{row:<22s}" + "".join(f"{v:14.4g}" for v in values)
        if ratio:
            line += f"{values[0] / values[1] if values[1] else float('nan'):10.3f}"
        lines.append(line)
    return "\n".join(lines) + "\n"

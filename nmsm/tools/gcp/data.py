"""Experimental inputs of GCP: foot kinematics from the full-body motion and the ground
reactions of each foot's force columns, on each foot's own time window.

Time grids: the motion's frames inside ``[start_time, end_time]`` define the window; they
must be evenly spaced (the kinematics are B-splines on equal increments). A window reaching
beyond the motion warns and uses the motion's frames inside it. Each frame takes
the ground-reaction row within 5 ms of it. When the two files are sampled
differently (no such row), the ground reactions are linearly interpolated onto the motion
frames, with a warning; when they do not cover the window, or the motion is unevenly
sampled, :class:`~nmsm.errors.InputError` names the files and what was expected.

Units: SI and radians; arrays have time along axis 0.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.motion_units import warn_implausible_angles
from nmsm.io.storage import Table, read_storage
from nmsm.model.components import GROUND, Model

#: largest time difference (s) between a motion frame and its ground-reaction row
TIME_MATCH_TOLERANCE = 5e-3
#: largest relative deviation of the motion's frame intervals from their mean
EVEN_SPACING_TOLERANCE = 1e-3
#: longest frame interval (s) of the motion: more is taken for times in milliseconds
LONGEST_FRAME_INTERVAL = 0.5
#: frames whose force magnitude exceeds this fraction of the window's peak count as loaded
LOADED_FRACTION = 0.05


@attrs.frozen(eq=False)
class GroundReactions:
    """One foot's plate data on the foot's frames: ``forces`` (T, 3) N, ``moments`` (T, 3)
    N m about ``electrical_center`` (T, 3) m, all in ground."""

    forces: np.ndarray
    moments: np.ndarray
    electrical_center: np.ndarray


def read_motion(path: Path, model: Model) -> Table:
    """The motion file in radians (rotational model coordinates converted from degrees); a
    header whose unit looks wrong warns (:mod:`nmsm.io.motion_units`)."""
    table = read_storage(path)
    rotational = {c.name: c.range for c in model.coordinates if c.is_rotational}
    warn_implausible_angles(table, rotational, file=path)
    return table.to_radians(rotational)


def read_ground_reactions(path: Path, electrical_center_columns: set[str]) -> Table:
    """The ground-reaction file; NaN allowed only in the electrical-center columns."""
    return read_storage(path, allow_nan=lambda label: label in electrical_center_columns)


def window_indices(time: np.ndarray, start: float, end: float, *, file: Path, element: str,
                   settings_file: Path | str | None = None) -> np.ndarray:
    """Indices of the frames with ``start <= t <= end`` (1e-9 s slack); at least 2 frames
    evenly spaced, else :class:`InputError`. A window reaching more than half a frame
    beyond the motion warns (``settings_file``, ``element``, requested and available range)
    and keeps the motion's frames inside it."""
    slack = 1e-9
    idx = np.flatnonzero((time >= start - slack) & (time <= end + slack))
    if idx.size < 2:
        raise InputError(f"fewer than 2 frames of the motion lie in [{start}, {end}] s "
                         f"(file covers {time[0]}..{time[-1]} s)", file=file,
                         element=f"{element}: <start_time>/<end_time>",
                         expected="start_time and end_time inside the motion's time range")
    half_frame = 0.5 * float(np.median(np.diff(time)))
    beyond = [name for name, out in (("<start_time>", start < time[0] - half_frame),
                                     ("<end_time>", end > time[-1] + half_frame)) if out]
    if beyond:
        where = f"{settings_file}: " if settings_file else ""
        verb = "ask" if len(beyond) > 1 else "asks"
        warnings.warn(f"{where}{element}: {' and '.join(beyond)} {verb} for {start:g}-{end:g} s but the motion {file} "
                      f"covers {time[0]:g}-{time[-1]:g} s; using its frames in {time[idx[0]]:g}-{time[idx[-1]]:g} s",
                      stacklevel=3)
    steps = np.diff(time[idx])
    mean = float(steps.mean())
    if mean > LONGEST_FRAME_INTERVAL:
        raise InputError(f"motion frames in [{start}, {end}] s are {mean:.6g} s apart: are the times in milliseconds?",
                         file=file, element="column 'time'",
                         expected=f"times in seconds, frames at most {LONGEST_FRAME_INTERVAL} s apart (the kinematics "
                         "filter and the contact model's velocities take the time column in seconds)")
    if np.abs(steps - mean).max() > EVEN_SPACING_TOLERANCE * mean:
        raise InputError(f"motion frames in [{start}, {end}] s are not evenly spaced "
                         f"(intervals {steps.min():.6g}..{steps.max():.6g} s)", file=file,
                         expected="equal time increments (resample the motion first)")
    return idx


def match_rows(motion_time: np.ndarray, grf: Table, grf_file: Path, motion_file: Path) -> np.ndarray | None:
    """Row index of ``grf`` within 5 ms of each motion time, ``None`` when some motion time
    has no such row (interpolation needed); :class:`InputError` when ``grf`` does not cover
    the motion times."""
    covered = grf.time[0] - TIME_MATCH_TOLERANCE <= motion_time[0] and motion_time[-1] <= grf.time[-1] + TIME_MATCH_TOLERANCE
    if not covered:
        raise InputError(f"ground reactions cover {grf.time[0]}..{grf.time[-1]} s but the foot's window is "
                         f"{motion_time[0]}..{motion_time[-1]} s (motion file {motion_file})", file=grf_file,
                         expected="ground reactions over the whole time window")
    nearest = np.clip(np.searchsorted(grf.time, motion_time), 1, grf.n_rows - 1)
    left, right = grf.time[nearest - 1], grf.time[nearest]
    nearest = np.where(np.abs(motion_time - left) <= np.abs(right - motion_time), nearest - 1, nearest)
    if np.all(np.abs(grf.time[nearest] - motion_time) <= TIME_MATCH_TOLERANCE):
        return nearest
    return None


def foot_ground_reactions(grf: Table, motion_time: np.ndarray, force_columns: tuple[str, ...],
                          moment_columns: tuple[str, ...], center_columns: tuple[str, ...], *,
                          grf_file: Path, motion_file: Path, settings_file: Path | None, line: int | None,
                          surface: str | None = None) -> GroundReactions:
    """The foot's ground reactions on the motion frames (module docstring); ``surface``
    (e.g. ``<GCPContactSurface> Left foot``) prefixes the element in error messages."""
    where = f"{surface}: " if surface else ""
    for element, columns in (("force_columns", force_columns), ("moment_columns", moment_columns),
                             ("electrical_center_columns", center_columns)):
        if len(columns) != 3:
            raise InputError(f"<{element}> names {len(columns)} columns", file=settings_file, line=line,
                             element=f"{where}<{element}>", expected="three column names (X Y Z)")
        for label in columns:
            if not grf.has(label):
                missing = grf.missing_column(label)
                raise InputError(f"<{element}> names column '{label}', which {grf_file} does not have "
                                 f"({missing.detail})", file=settings_file, line=line,
                                 element=f"{where}<{element}>",
                                 expected=f"columns of {grf_file.name}: {', '.join(grf.labels)}")
    rows = match_rows(motion_time, grf, grf_file, motion_file)
    labels = list(force_columns) + list(moment_columns) + list(center_columns)
    values = grf.columns(labels)
    if rows is not None:
        values = values[rows]
    else:
        inside = (grf.time >= motion_time[0] - TIME_MATCH_TOLERANCE) & (grf.time <= motion_time[-1] + TIME_MATCH_TOLERANCE)
        times = grf.time[inside] if inside.sum() > 2 else grf.time  # the motion's window, if it holds rows
        steps = np.diff(times)
        gap = ""
        if steps.size > 1 and steps.max() > 1.5 * np.median(steps):  # rows missing, not another rate
            k = int(np.argmax(steps))
            gap = (f" (rows are missing: a gap of {float(steps[k]):.6g} s after {float(times[k]):g} s, where the file "
                   f"is otherwise sampled every {float(np.median(steps)):.6g} s)")
        warnings.warn(f"{grf_file}: ground reactions sampled at other times than the motion {motion_file}{gap}; "
                      "linearly interpolated onto the motion frames", stacklevel=2)
        values = np.column_stack([np.interp(motion_time, grf.time, values[:, k]) for k in range(values.shape[1])])
    forces, moments, center = values[:, 0:3], values[:, 3:6], values[:, 6:9]
    bad = np.isnan(center).any(axis=1)
    # a plate reports no centre where it sees no contact; resampling (splines of the force
    # columns) leaves small ripples there (< 0.1 % of the peak force): no contact either
    magnitude = np.abs(forces).max(axis=1)
    ripple = bad & (magnitude <= max(1e-6, 1e-3 * float(np.nanmax(magnitude, initial=0.0))))
    forces = np.where(ripple[:, None], 0.0, forces)
    moments = np.where(ripple[:, None], 0.0, moments)
    if np.any(bad & (np.abs(forces).max(axis=1) > 1e-6)):
        raise InputError(f"electrical-center columns {', '.join(center_columns)} are NaN while the foot is "
                         "loaded", file=grf_file, element="<electrical_center_columns>",
                         expected="the point the plate moments are about (finite wherever there is force)")
    center = np.where(np.isnan(center), 0.0, center)
    if np.isnan(forces).any() or np.isnan(moments).any():
        raise InputError("force or moment columns contain NaN in the window", file=grf_file,
                         expected="finite forces and moments")
    check_force_layout(forces, force_columns, motion_time, grf_file=grf_file, settings_file=settings_file, line=line)
    return GroundReactions(forces, moments, center)


def check_force_layout(forces: np.ndarray, force_columns: tuple[str, ...], motion_time: np.ndarray, *,
                       grf_file: Path, settings_file: Path | None, line: int | None) -> None:
    """:class:`InputError` when the Y (vertical) force column is not the dominant, mostly
    positive force in the window: its peak below a horizontal column's peak magnitude, or
    negative in most loaded frames (those above ``LOADED_FRACTION`` of the peak force)."""
    magnitude = np.linalg.norm(forces, axis=1)
    peak = float(magnitude.max(initial=0.0))
    if peak <= 1e-6:
        return  # no load in the window: nothing to tell the layout from
    vertical = forces[:, 1]
    loaded = magnitude > LOADED_FRACTION * peak
    positive = float(np.mean(vertical[loaded] > 0.0))
    horizontal = max((0, 2), key=lambda k: float(np.abs(forces[:, k]).max()))
    horizontal_peak = float(np.abs(forces[:, horizontal]).max())
    reasons = []
    if positive < 0.5:
        reasons.append(f"it is negative in {1 - positive:.0%} of the loaded frames (down to {vertical.min():.4g} N)")
    if 0.0 < vertical.max() < horizontal_peak:
        reasons.append(f"its peak {vertical.max():.4g} N is below the peak magnitude {horizontal_peak:.4g} N of "
                       f"'{force_columns[horizontal]}'")
    if not reasons:
        return
    found = "; ".join(reasons)
    where = f" (named in {settings_file}{'' if line is None else f':{line}'})" if settings_file else ""
    raise InputError(
        f"columns {' '.join(force_columns)}{where}: the Y (vertical) column '{force_columns[1]}' is not the "
        f"vertical ground reaction in {motion_time[0]:.6g}..{motion_time[-1]:.6g} s: {found}",
        file=grf_file, element="<force_columns>",
        expected="force columns ordered X, Y, Z with Y the vertical (upward) ground reaction on the foot: "
                 "the largest force, positive while the foot is loaded")


def full_coordinates(motion: Table, model: Model, rows: np.ndarray, body: str, *, motion_file: Path) -> np.ndarray:
    """Model coordinate values (T, n) on ``rows`` of ``motion``: missing columns take the
    default value, except coordinates moving ``body`` (an error)."""
    names = model.coordinate_names
    needed = set(_ancestor_coordinates(model, body))
    out = np.zeros((rows.size, len(names)))
    for k, name in enumerate(names):
        if motion.has(name):
            out[:, k] = motion.column(name)[rows]
        elif name in needed:
            raise InputError(f"the motion has no column for coordinate '{name}', which moves '{body}'",
                             file=motion_file, element=f"column '{name}'",
                             expected="every coordinate between ground and the hindfoot")
        else:
            out[:, k] = model.coordinate(name).default_value
    return out


def _ancestor_coordinates(model: Model, body: str) -> list[str]:
    by_child = {j.child_body: j for j in model.joints}
    coordinates: list[str] = []
    current = body
    while current != GROUND and current in by_child:
        joint = by_child[current]
        coordinates.extend(joint.coordinates)
        current = joint.parent_body
    coupled = model.coupled_coordinates
    for name in list(coordinates):
        if name in coupled:
            coordinates.extend(coupled[name].independent)
    return coordinates

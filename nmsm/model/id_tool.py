"""Inverse dynamics of a recorded motion, as OpenSim's Inverse Dynamics tool computes it.

:func:`inverse_dynamics_of_motion` takes coordinates over time (an IK ``.mot``), optionally
pads and low-pass filters them (:mod:`nmsm.model.signal`), converts degrees of rotational
coordinates to radians, differentiates them through a natural quintic interpolating
spline, applies external loads (:mod:`nmsm.model.external_loads`) and evaluates nmsm's
inverse dynamics (muscles excluded; contact forces of the model included) at the motion's
own times. The result is a :class:`~nmsm.io.storage.Table` labelled as OpenSim labels
it: ``<coordinate>_moment`` for rotational and ``<coordinate>_force`` for translational
and coupled coordinates, in multibody tree order, N m and N.

The motion is matched to the model's coordinates by :func:`check_motion_columns` (shared by
``nmsm markers`` and the muscle analysis): no matching column is an error; absent
coordinates, unknown columns and an implausible ``inDegrees`` header warn. A time range
outside the motion is an error naming the file and both ranges (:func:`frames_in_range`).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import numpy as np

from nmsm.core.threads import SOLVER_THREADS
from nmsm.errors import InputError
from nmsm.io.storage import Table, table_from_columns
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.components import GROUND, Model
from nmsm.model.external_loads import ExternalLoads, sample_loads
from nmsm.model.signal import lowpass_iir, pad, quintic_spline, uniform_interval


#: names listed in a message before "and N more"
NAMED_COLUMNS = 5


#: a motion whose frames are further apart than this (s) is reported (times in milliseconds?)
SLOW_FRAME_INTERVAL = 0.5


def _few(names: Sequence[str]) -> str:
    """The first :data:`NAMED_COLUMNS` names, then 'and N more'."""
    text = ", ".join(names[:NAMED_COLUMNS])
    return text + (f" and {len(names) - NAMED_COLUMNS} more" if len(names) > NAMED_COLUMNS else "")


def _coordinate_columns(motion: Table) -> dict[str, int]:
    """Name -> column index of a motion whose labels are coordinate names or state paths
    (``/jointset/j/c/value``: the name is ``c``); other state paths (``.../speed``,
    ``/forceset/...``) name no coordinate and are left out."""
    by_name: dict[str, int] = {}
    for j, label in enumerate(motion.labels):
        name = label
        if label.startswith("/"):
            parts = label.strip("/").split("/")
            if parts[-1] != "value" or len(parts) < 2:
                continue
            name = parts[-2]
        by_name.setdefault(name, j)
    return by_name


def check_motion_columns(model: Model, motion: Table) -> list[str]:
    """Match a motion's columns to the model's coordinates; returns the coordinates absent
    from the motion (model order).

    :class:`InputError` naming the file, the model and the expected coordinates when no
    column names a coordinate; otherwise a warning listing the model's independent
    coordinates absent from the motion (dependent coordinates of couplers are computed) and
    the columns that name no model coordinate. The angle unit is checked against the model
    (:func:`nmsm.io.motion_units.warn_implausible_angles`).
    """
    from nmsm.io.motion_units import warn_implausible_angles

    by_name = _coordinate_columns(motion)
    names = model.coordinate_names
    known = set(names)
    missing = [n for n in names if n not in by_name]
    if len(missing) == len(names):
        raise InputError(f"no column names a coordinate of the model {model.name} ({model.file})",
                         file=motion.source, line=motion.label_line, element="column labels",
                         expected=f"columns named after the model's coordinates: {_few(names)}")
    unknown = [motion.labels[j] for n, j in by_name.items() if n not in known]
    absent = [n for n in missing if n not in model.coupled_coordinates]
    parts = []
    if absent:
        parts.append(f"coordinate(s) {_few(absent)} of the model {model.name} have no column (their default values "
                     "are used)")
    if unknown:
        parts.append(f"column(s) {_few(unknown)} are not coordinates of the model (ignored)")
    if parts:
        warnings.warn(f"{motion.source or 'motion'}: " + "; ".join(parts), stacklevel=3)
    rotational = {c.name: c.range for c in model.coordinates if c.motion_type == "rotational"}
    warn_implausible_angles(motion, rotational, file=motion.source, stacklevel=4)
    return missing


def motion_coordinates(model: Model, motion: Table) -> tuple[np.ndarray, list[str]]:
    """Coordinate values ``(n, n_coordinates)`` in model order (file units) from a motion
    table whose columns are coordinate names or state paths (``/jointset/j/c/value``),
    and the names of coordinates absent from the file (absent ones at their default values,
    in degrees for rotational coordinates of a file in degrees).

    The columns are checked against the model first (:func:`check_motion_columns`: an error
    when none matches, a warning for absent coordinates, unknown columns or an implausible
    angle unit).
    """
    if motion.n_rows == 0:
        raise InputError("the motion has column labels but no rows", file=motion.source,
                         expected="at least one row of coordinate values after the column labels")
    missing = check_motion_columns(model, motion)
    by_name = _coordinate_columns(motion)
    values = np.zeros((motion.n_rows, len(model.coordinates)))
    for i, c in enumerate(model.coordinates):
        if c.name in by_name:
            values[:, i] = motion.data[:, by_name[c.name]]
        elif motion.in_degrees and c.motion_type == "rotational":
            values[:, i] = np.rad2deg(c.default_value)  # file units: callers convert every rotational column
        else:
            values[:, i] = c.default_value
    return values, missing


def frames_in_range(times: np.ndarray, time_range: tuple[float, float] | None, source: object = None) -> np.ndarray:
    """``(n,)`` True for the frames of ``times`` (s) within ``time_range`` (s, inclusive, to
    1e-12 s; None: every frame; an infinite bound is open). :class:`InputError` naming
    ``source``, the range asked and the range the file covers when a bound is not a number,
    the range starts after it ends, or no frame lies in it."""
    if time_range is None:
        return np.ones(times.size, dtype=bool)
    start, end = (float(b) for b in time_range)
    asked = f"{start:g}-{end:g} s"
    covers = f"the file covers {times[0]:g}-{times[-1]:g} s"
    if np.isnan(start) or np.isnan(end):
        raise InputError(f"the time range {asked} has a bound that is not a number ({covers})", file=source,
                         element="time range", expected="numeric start and end times (s)")
    if start > end:
        raise InputError(f"the time range {asked} starts after it ends ({covers})", file=source,
                         element="time range", expected="a start time no later than the end time")
    keep = (times >= start - 1e-12) & (times <= end + 1e-12)
    if not keep.any():
        raise InputError(f"no frame lies in the time range {asked} ({covers})", file=source, element="time range",
                         expected="a time range overlapping the motion")
    return keep


def generalized_force_labels(model: Model) -> list[str]:
    """OpenSim's ID column labels in multibody tree order."""
    kinds = {c.name: c.motion_type for c in model.coordinates}
    return [f"{name}_moment" if kinds[name] == "rotational" else f"{name}_force" for name in model.tree_coordinate_names]


def inverse_dynamics_of_motion(
    model: Model,
    motion: Table,
    *,
    external_loads: ExternalLoads | None = None,
    load_table: Table | None = None,
    lowpass_hz: float | None = None,
    time_range: tuple[float, float] | None = None,
    casadi_model: CasadiModel | None = None,
) -> Table:
    """Generalized forces over the motion's times (see module docstring)."""
    cm = casadi_model if casadi_model is not None else CasadiModel(model)
    values, missing = motion_coordinates(model, motion)
    coupled = model.coupled_coordinates
    times = motion.time.copy()
    if times.size < 6:
        raise InputError(f"{times.size} rows are too few", file=motion.source, expected="at least 6 rows")
    step = float(np.median(np.diff(times)))
    if step > SLOW_FRAME_INTERVAL:
        warnings.warn(f"{motion.source or 'motion'}: frames are {step:.6g} s apart: are the times in milliseconds? "
                      "Velocities and accelerations are per second of the time column (in ms they are 1e3 and 1e6 "
                      "times too small)", stacklevel=2)
    keep = frames_in_range(times, time_range, motion.source)
    out_times = times[keep]
    fit_times, fit_values = times, values
    if lowpass_hz is not None and lowpass_hz > 0:
        n_pad = times.size // 2
        fit_times = pad(times, n_pad)
        fit_values = lowpass_iir(pad(values, n_pad), uniform_interval(times, source=motion.source), lowpass_hz)
    if motion.in_degrees:
        rotational = [i for i, c in enumerate(model.coordinates) if c.motion_type == "rotational"]
        fit_values = fit_values.copy()
        fit_values[:, rotational] = np.deg2rad(fit_values[:, rotational])
    q, qd, qdd = quintic_spline(fit_times, fit_values, out_times)
    dependent = [name for name in missing if name in coupled]
    if dependent:
        index = cm.coordinates.independent_indices
        full = cm.coordinates.expand.map(out_times.size)(q[:, index].T, qd[:, index].T, qdd[:, index].T)
        for i, name in enumerate(model.coordinate_names):
            if name in dependent:
                q[:, i], qd[:, i], qdd[:, i] = (np.array(a)[i] for a in full)
    other = [f for f in model.other_forces if f.applies_force]
    if other:
        warnings.warn(f"{model.file}: force elements not modeled by nmsm are left out of inverse dynamics: "
                      + ", ".join(f"{f.type} '{f.name}'" for f in other), stacklevel=2)
    contact = [f for f in model.contact_forces if f.applies_force]
    include_contact = bool(contact)
    columns = [q.T, qd.T, qdd.T]
    bodies: Sequence[str] = ()
    if external_loads is not None and external_loads.forces:
        if contact:
            names = ", ".join(f.name for f in contact[:4]) + (f" and {len(contact) - 4} more" if len(contact) > 4 else "")
            warnings.warn(f"{model.file}: the model's contact forces (SmoothSphereHalfSpaceForce {names}) act in "
                          f"inverse dynamics together with the external loads of {external_loads.source}; if "
                          "these are the measured ground reactions, the feet are loaded twice: set the contact "
                          "forces' <appliesForce> to false in a copy of the model to leave them out", stacklevel=2)
        sampled = sample_loads(external_loads, out_times, load_table)
        bodies = tuple(s.spec.body for s in sampled)
        for body in bodies:
            if body not in model.bodies:
                raise InputError(f"external force on body '{body}', which the model does not have",
                                 file=external_loads.source, element="applied_to_body",
                                 expected="one of " + ", ".join(model.bodies))
        columns.append(_ground_loads(cm, sampled, q))
    function = cm.inverse_dynamics_function(bodies, include_contact=include_contact)
    tau = np.array(function.map(out_times.size, "thread", SOLVER_THREADS)(*columns)).T  # (m, n) model order
    _check_finite(tau, out_times, model, motion, values)
    order = [model.coordinate_index(name) for name in model.tree_coordinate_names]
    labels = generalized_force_labels(model)
    return table_from_columns(out_times, {label: tau[:, i] for label, i in zip(labels, order)},
                              name="Inverse Dynamics Generalized Forces")


def _check_finite(tau: np.ndarray, times: np.ndarray, model: Model, motion: Table, values: np.ndarray) -> None:
    """Refuse generalized forces ``tau`` ``(m, n_coordinates)`` that are not finite (values
    so large that the dynamics overflow), naming the motion, the first frame and the largest
    coordinate value."""
    bad = ~np.isfinite(tau).all(axis=1)
    if not bad.any():
        return
    first = int(np.flatnonzero(bad)[0])
    largest = int(np.unravel_index(np.argmax(np.abs(values)), values.shape)[1]) if values.size else 0
    name = model.coordinates[largest].name if model.coordinates else "?"
    raise InputError(f"inverse dynamics is not finite at {int(bad.sum())} of {times.size} frames (first at t = "
                     f"{times[first]:g} s): the motion's values are out of range (largest: {name} "
                     f"{np.abs(values).max():.3g})", file=motion.source, element=f"column '{name}'",
                     expected="coordinate values within the model's range (radians, or degrees with inDegrees=yes; "
                     "metres)")


def _ground_loads(cm: CasadiModel, sampled: list, q: np.ndarray) -> np.ndarray:
    """Loads as a ``(9, n_loads * m)`` array (force, point, torque in ground) per frame."""
    m = q.shape[0]
    blocks = np.zeros((m, 9, len(sampled)))
    for k, load in enumerate(sampled):
        force = load.force.copy()
        torque = load.torque.copy()
        point = load.point
        body = load.spec.body
        frames = {load.spec.force_frame, load.spec.point_frame if point is not None else GROUND}
        poses = {}
        for frame in frames | ({body} if point is None else set()):
            if frame == GROUND:
                continue
            pose = cm.body_pose_function(frame).map(m)
            rotation, origin = pose(q.T)
            poses[frame] = (np.array(rotation).reshape(3, 3, m, order="F"), np.array(origin))
        if load.spec.force_frame != GROUND:
            rotation = poses[load.spec.force_frame][0]
            force = np.einsum("ijm,mj->mi", rotation, force)
            torque = np.einsum("ijm,mj->mi", rotation, torque)
        if point is None:
            point_g = poses[body][1].T
        elif load.spec.point_frame != GROUND:
            rotation, origin = poses[load.spec.point_frame]
            point_g = origin.T + np.einsum("ijm,mj->mi", rotation, point)
        else:
            point_g = point
        blocks[:, 0:3, k] = force
        blocks[:, 3:6, k] = point_g
        blocks[:, 6:9, k] = torque
    # Function.map expects the per-frame (9 x n_loads) matrices side by side
    return np.concatenate([blocks[i] for i in range(m)], axis=1)


"""Inverse dynamics of a recorded motion, as OpenSim's Inverse Dynamics tool computes it.

:func:`inverse_dynamics_of_motion` takes coordinates over time (an IK ``.mot``), optionally
pads and low-pass filters them (:mod:`nmsm.model.signal`), converts degrees of rotational
coordinates to radians, differentiates them through a natural quintic interpolating
spline, applies external loads (:mod:`nmsm.model.external_loads`) and evaluates nmsm's
inverse dynamics (muscles excluded; contact forces of the model included) at the motion's
own times. The result is a :class:`~nmsm.io.storage.Table` labelled as OpenSim labels
it: ``<coordinate>_moment`` for rotational and ``<coordinate>_force`` for translational
and coupled coordinates, in multibody tree order, N m and N.
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


def motion_coordinates(model: Model, motion: Table) -> tuple[np.ndarray, list[str]]:
    """Coordinate values ``(n, n_coordinates)`` in model order (file units) from a motion
    table whose columns are coordinate names or state paths (``/jointset/j/c/value``),
    and the names of coordinates absent from the file."""
    by_name: dict[str, int] = {}
    for j, label in enumerate(motion.labels):
        name = label
        if label.startswith("/"):
            parts = label.strip("/").split("/")
            if parts[-1] != "value":
                continue
            name = parts[-2]
        by_name.setdefault(name, j)
    values = np.zeros((motion.n_rows, len(model.coordinates)))
    missing = []
    for i, c in enumerate(model.coordinates):
        if c.name in by_name:
            values[:, i] = motion.data[:, by_name[c.name]]
        else:
            missing.append(c.name)
            values[:, i] = c.default_value
    return values, missing


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
    absent = [name for name in missing if name not in coupled]
    if absent:
        warnings.warn(f"{motion.source}: no column for coordinates {', '.join(absent)}; their default values are used",
                      stacklevel=2)
    times = motion.time.copy()
    if times.size < 6:
        raise InputError(f"{times.size} rows are too few", file=motion.source, expected="at least 6 rows")
    if time_range is None:
        keep = np.ones(times.size, dtype=bool)
    else:
        keep = (times >= time_range[0] - 1e-12) & (times <= time_range[1] + 1e-12)
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
    include_contact = any(f.applies_force for f in model.contact_forces)
    columns = [q.T, qd.T, qdd.T]
    bodies: Sequence[str] = ()
    if external_loads is not None and external_loads.forces:
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
    order = [model.coordinate_index(name) for name in model.tree_coordinate_names]
    labels = generalized_force_labels(model)
    return table_from_columns(out_times, {label: tau[:, i] for label, i in zip(labels, order)},
                              name="Inverse Dynamics Generalized Forces")


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


"""Write a treatment solution as the original does (docs/treatment.md, 'Outputs'), on the ``nodes`` grid.

Files (``<trial>`` = ``trial_name``):

``IKData/<trial>.sto``                 every model coordinate (rad, m)
``IDData/<trial>.sto``                 inverse dynamics of the solution (N·m, N), ID labels
``GRFData/<trial>.sto``                modeled ground reactions of the contact models (force N,
                                       point m, moment N·m about the point; osimx column names)
``<trial>_states.sto``                 ``q`` and ``q_u`` of the state coordinates
``<trial>_accelerations.sto``          ``q̈`` of the state coordinates
``<trial>_mocoTrajectory.sto``         the states and the controllers' controls named by OpenSim
                                       component path, with Moco's header counts: opens as
                                       ``opensim.MocoTrajectory(path)`` (:mod:`nmsm.interop.moco_trajectory`)
``<trial>_torqueControls.sto`` ...     each controller's tables (torque controls, synergy
                                       commands, synergy weights, combined activations)
``<trial>_parameterSolution.xml``      DO static parameters (when any)
``<trial>_convergence.txt``            IPOPT status, cost per term, active/violated constraints
``Analysis/<trial>_trackedPositions.sto`` / ``_modeledPositions.sto`` etc.: tracked and
                                       modeled state kinematics on the same times
``Analysis/<trial>_statesInterpolated.sto`` the states between the nodes through each mesh
                                       interval's collocation polynomial (:data:`SAMPLES_PER_POINT`
                                       samples per collocation point; what the figures draw);
                                       ``_trackedInterpolated.sto`` the tracked kinematics at the
                                       same times
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from nmsm.interop.moco_trajectory import (
    MocoColumns,
    coordinate_speed_path,
    coordinate_value_path,
    write_moco_trajectory,
)
from nmsm.io.storage import table_from_columns, write_storage
from nmsm.tools.treatment.formulation import speed_label
from nmsm.tools.treatment.solution import TreatmentSolution


#: samples of ``Analysis/<trial>_statesInterpolated.sto`` per collocation point of a mesh interval
SAMPLES_PER_POINT = 4


def dense_normalized_times(tsol: TreatmentSolution) -> np.ndarray:
    """Normalized times in [0, 1]: in each mesh interval :data:`SAMPLES_PER_POINT` evenly
    spaced points per collocation point of the interval (its start included), then 1."""
    mesh = tsol.built.trajectory.phase.mesh
    starts = mesh.interval_starts
    pieces = [np.linspace(a, b, SAMPLES_PER_POINT * n + 1)[:-1]
              for a, b, n in zip(starts[:-1], starts[1:], mesh.points)]
    return np.concatenate([*pieces, [1.0]])


def write_table(path: Path, time: np.ndarray, labels: Sequence[str], values: np.ndarray, name: str = "") -> Path:
    """Write ``values`` (n, k) with ``labels`` and ``time`` (n,) as an OpenSim table."""
    values = np.asarray(values, dtype=float).reshape(len(time), len(labels))
    table = table_from_columns(time, {label: values[:, j] for j, label in enumerate(labels)}, name=name or path.stem)
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_storage(path, table)


def write_solution(stage: Path, tsol: TreatmentSolution, *, summary: str | None = None,
                   extra_tables: Mapping[str, tuple] | None = None) -> list[Path]:
    """Write every output file of ``tsol`` into ``stage``; returns the paths."""
    built = tsol.built
    data = built.data
    model = data.model
    trial = tsol.trial_name
    t = tsol.time
    coords = model.coordinate_names
    out = [
        write_table(stage / "IKData" / f"{trial}.sto", t, coords, tsol.positions),
        write_table(stage / "IDData" / f"{trial}.sto", t, [model.load_label(c) for c in coords], tsol.inverse_dynamics),
    ]
    contacts = getattr(data, "contact_models", [])
    if contacts:
        labels, columns = [], []
        for contact in contacts:
            force, moment, point = (tsol.value(x) for x in built.context._q.ground_reaction(tsol.grid, contact))
            labels += [*contact.force_labels, *contact.point_labels, *contact.moment_labels]
            columns += [force, point, moment]
        out.append(write_table(stage / "GRFData" / f"{trial}.sto", t, labels, np.hstack(columns)))
    sc = data.state_coordinates
    out.append(write_table(stage / f"{trial}_states.sto", t, list(sc) + [speed_label(c) for c in sc], tsol.states))
    out.append(write_table(stage / f"{trial}_accelerations.sto", t, sc, tsol.state_accelerations))
    tables: dict[str, tuple] = {}
    for controller in data.controllers:
        tables.update(controller.output_tables(tsol))
    tables.update(extra_tables or {})
    for name, entry in tables.items():
        labels, values = entry[0], np.asarray(entry[1], dtype=float)
        if len(entry) > 2:
            time = np.asarray(entry[2], dtype=float)
        else:
            time = t if values.shape[0] == t.size else np.arange(1.0, values.shape[0] + 1)
        out.append(write_table(stage / name, time, labels, values))
    s_dense = dense_normalized_times(tsol)
    dense = built.trajectory.sample(tsol.solution, s_dense)
    state_labels = list(sc) + [speed_label(c) for c in sc]
    out.append(write_table(stage / "Analysis" / f"{trial}_statesInterpolated.sto", dense["time"], state_labels,
                           dense["states"][:, :2 * len(sc)]))
    tracked_dense = data.tracked_full_kinematics(s_dense * data.reference_duration)
    state_idx = [coords.index(c) for c in sc]
    out.append(write_table(stage / "Analysis" / f"{trial}_trackedInterpolated.sto", dense["time"], state_labels,
                           np.hstack([tracked_dense[0][:, state_idx], tracked_dense[1][:, state_idx]])))
    out.append(write_moco_trajectory(stage / f"{trial}_mocoTrajectory.sto", t, moco_columns(tsol), name=trial))
    # tracked vs modeled kinematics of the states, on the same times
    ref_t = tsol.view.normalized_time * data.reference_duration
    tracked = data.tracked_full_kinematics(ref_t)
    idx = [coords.index(c) for c in sc]
    for kind, modeled, reference in (("Positions", tsol.positions, tracked[0]), ("Velocities", tsol.speeds, tracked[1]),
                                     ("Accelerations", tsol.accelerations, tracked[2])):
        out.append(write_table(stage / "Analysis" / f"{trial}_modeled{kind}.sto", t, sc, modeled[:, idx]))
        out.append(write_table(stage / "Analysis" / f"{trial}_tracked{kind}.sto", t, sc, reference[:, idx]))
    if summary is not None:
        path = stage / f"{trial}_convergence.txt"
        path.write_text(summary + "\n", encoding="utf-8")
        out.append(path)
    return out


def moco_columns(tsol: TreatmentSolution) -> MocoColumns:
    """The solution's Moco trajectory columns: each state coordinate's value and speed, then
    every controller's own states and controls (:meth:`Controller.moco_columns`)."""
    data = tsol.built.data
    sc = list(data.state_coordinates)
    columns = MocoColumns()
    joints = {c: data.model.coordinate_joint(c) for c in sc}
    for j, c in enumerate(sc):
        columns.states[coordinate_value_path(joints[c], c)] = tsol.states[:, j]
    for j, c in enumerate(sc):
        columns.states[coordinate_speed_path(joints[c], c)] = tsol.states[:, len(sc) + j]
    for controller in data.controllers:
        extra = controller.moco_columns(tsol)
        if extra is not None:
            columns.update(extra)
    return columns

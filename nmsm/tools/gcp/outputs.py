"""GCP result files (docs/gcp.md, 'Outputs'), written into a staging folder.

Per foot ``<n>`` (1-based), with ``<model>`` the input model's file stem:

* ``<model>_Foot_<n>_experimentalFootKinematics.sto`` / ``_optimizedFootKinematics.sto``:
  columns toe coordinate, ``Rotation1..3``, ``Translation1..3`` (rad, m);
* ``<model>_Foot_<n>_replacedExperimentalGroundReactions.sto``: the plate's reactions as the
  final task compares them (moved to the experimental midfoot-superior point at height L0,
  electrical-center shift and plate rotation applied), columns ``Fx Fy Fz Mx My Mz ECx ECy
  ECz`` with ``EC`` that point;
* ``<model>_Foot_<n>_optimizedGroundReactions.sto``: the contact model's reactions, ``EC``
  the modeled midfoot-superior point projected on the floor at height L0 (the original
  writes the experimental point there although its moments are about the modeled one).

When every foot has the same window:

* ``GRFData/gcp_modeled_<grf>`` and ``_CoP``: the modeled reactions under the GRF file's
  column names of each foot (force, point, moment), low-passed (2nd-order, 6 Hz); the
  ``_CoP`` variant moves the point to the centre of pressure (frames with F_y > 5 N) and
  keeps only the free moment;
* ``GRFData/gcp_adjusted<grf>`` and ``_CoP`` (only when a task optimized an
  electrical-center shift or plate rotation): the input GRF file on the window with each
  foot's columns corrected (rotated force and moment, shifted point);
* ``IKData/gcp_modeled_<motion>``: the full-body motion re-solved with the modeled foot
  markers (:mod:`nmsm.tools.gcp.ik_update`), degrees for rotational coordinates.

``<osimx or model stem>_gcp.osimx`` holds the contact surfaces (appended to the input
``.osimx``'s, replacing a surface on the same hindfoot), ``<model>_gcpErrors.txt`` the
error table (:mod:`nmsm.tools.gcp.report`), ``commandWindowOutput.txt`` the run's solver
summaries, and the settings file is copied in.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.io.osimx import GcpSpring, OsimxContactSurface, OsimxModel
from nmsm.io.storage import Table, table_from_columns, write_storage
from nmsm.tools.gcp.filtering import lowpass
from nmsm.tools.gcp.foot_model import FOOT_COORDINATES
from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.state import GcpState
from nmsm.tools.gcp.values import FootValues, as_array, plate_rotation_matrix

#: low-pass of the modeled ground reactions: (order, cutoff Hz)
GRF_FILTER = (2, 6.0)
#: centre-of-pressure conversion threshold on the vertical force (N)
COP_FORCE_THRESHOLD = 5.0
REACTION_LABELS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz", "ECx", "ECy", "ECz")


def kinematics_table(foot: FootInputs, coordinates: np.ndarray) -> Table:
    """Foot coordinates (T, 7) as a table named by the toe coordinate and Rotation/Translation."""
    labels = (foot.foot.toe_coordinate,) + FOOT_COORDINATES[1:]
    return Table(time=foot.time, labels=labels, data=np.asarray(coordinates, dtype=float), name="footKinematics")


def reactions_table(time: np.ndarray, forces: np.ndarray, moments: np.ndarray, point: np.ndarray) -> Table:
    """``Fx..Fz, Mx..Mz, ECx..ECz`` from (T, 3) arrays."""
    return Table(time=time, labels=REACTION_LABELS, data=np.hstack([forces, moments, point]), name="groundReactions")


def reference_points(foot: FootInputs, values: FootValues, resting_length: float) -> tuple[np.ndarray, np.ndarray]:
    """``(experimental, modeled)`` midfoot-superior points (T, 3) at height ``resting_length``."""
    experimental = foot.midfoot.copy()
    experimental[:, 1] = resting_length
    modeled = as_array(values.markers).T.reshape(foot.n_frames, 5, 3)[:, 4, :].copy()
    modeled[:, 1] = resting_length
    return experimental, modeled


def center_of_pressure(data: np.ndarray) -> np.ndarray:
    """The original's ``makeCoPData``: (T, 9) ``[F, point, M]`` -> centre of pressure and
    free moment where ``F_y`` > 5 N; ``M_x = M_z = 0`` everywhere."""
    out = data.copy()
    f, p, m = data[:, 0:3], data[:, 3:6], data[:, 6:9]
    convert = f[:, 1] > COP_FORCE_THRESHOLD
    fy = np.where(convert, f[:, 1], 1.0)
    qx = p[:, 0] + m[:, 2] / fy
    qz = p[:, 2] - m[:, 0] / fy
    out[convert, 3] = qx[convert]
    out[convert, 5] = qz[convert]
    free = m[:, 1] + f[:, 0] * (p[:, 2] - qz) - f[:, 2] * (p[:, 0] - qx)
    out[convert, 7] = free[convert]
    out[:, 6] = 0.0
    out[:, 8] = 0.0
    return out


def _foot_columns(foot: FootInputs) -> list[str]:
    s = foot.surface
    return list(s.force_columns) + list(s.electrical_center_columns) + list(s.moment_columns)


def modeled_grf_tables(feet: Sequence[FootInputs], values: Sequence[FootValues],
                       resting_lengths: Sequence[float]) -> tuple[Table, Table]:
    """``(modeled, modeled CoP)`` tables in the GRF file's column names (module docstring);
    ``resting_lengths`` (m) per foot."""
    time = feet[0].time
    columns: dict[str, np.ndarray] = {}
    cop: dict[str, np.ndarray] = {}
    order, cutoff = GRF_FILTER
    for foot, v, rest in zip(feet, values, resting_lengths):
        _, point = reference_points(foot, v, rest)
        data = np.hstack([as_array(v.forces).T, point, as_array(v.moments).T])
        filtered = lowpass(time, data, order, cutoff)
        filtered_cop = lowpass(time, center_of_pressure(data), order, cutoff)
        for k, label in enumerate(_foot_columns(foot)):
            columns[label] = filtered[:, k]
            cop[label] = filtered_cop[:, k]
    return table_from_columns(time, columns, name="gcp_modeled"), table_from_columns(time, cop, name="gcp_modeled")


@attrs.frozen
class PlateCorrection:
    """One foot's final plate corrections: shift (3,) m, rotation rad, resting length m."""

    shift: np.ndarray
    rotation: float
    resting_length: float


def adjusted_grf_tables(grf: Table, feet: Sequence[FootInputs], corrections: Sequence[PlateCorrection]
                        ) -> tuple[Table, Table]:
    """The input GRF on the window with each foot's plate corrections (rotated force and
    moment about the shifted, rotated electrical center), and its CoP variant."""
    time = feet[0].time
    rows = np.array([int(np.argmin(np.abs(grf.time - t))) for t in time])
    columns = {label: grf.column(label)[rows].copy() for label in grf.labels}
    cop = {label: values.copy() for label, values in columns.items()}
    for foot, c in zip(feet, corrections):
        r = foot.reactions
        rotation = np.array(plate_rotation_matrix(c.rotation))
        point = foot.midfoot.copy()
        point[:, 1] = c.resting_length
        center = point + (r.electrical_center + c.shift - point) @ rotation.T
        data = np.hstack([r.forces @ rotation.T, center, r.moments @ rotation.T])
        converted = center_of_pressure(data)
        for k, label in enumerate(_foot_columns(foot)):
            columns[label] = data[:, k]
            cop[label] = converted[:, k]
    return table_from_columns(time, columns, name="gcp_adjusted"), table_from_columns(time, cop, name="gcp_adjusted")


def contact_surface(foot: FootInputs, state: GcpState) -> OsimxContactSurface:
    """The ``.osimx`` entry of one foot with the final properties."""
    s = foot.surface
    springs = tuple(GcpSpring(name=name, parent_body=body, location=tuple(float(v) for v in loc),
                              spring_constant=float(k))
                    for name, body, loc, k in zip(foot.springs.names, foot.springs.bodies, foot.springs.locations,
                                                  state.spring_constants))
    return OsimxContactSurface(
        is_left_foot=s.is_left_foot, belt_speed=s.belt_speed, force_columns=tuple(s.force_columns),
        moment_columns=tuple(s.moment_columns), electrical_center_columns=tuple(s.electrical_center_columns),
        hindfoot_body=s.hindfoot_body, toe_marker=s.toe_marker, medial_marker=s.medial_marker,
        lateral_marker=s.lateral_marker, heel_marker=s.heel_marker,
        midfoot_superior_marker=s.midfoot_superior_marker,
        resting_spring_length=state.resting_spring_length,
        dynamic_friction_coefficient=state.dynamic_friction_coefficient,
        viscous_friction_coefficient=state.viscous_friction_coefficient,
        damping_factor=state.damping_factor, latching_velocity=state.latching_velocity, springs=springs)


def osimx_model(base: OsimxModel | None, model_name: str, model_file: str,
                surfaces: Sequence[OsimxContactSurface]) -> OsimxModel:
    """``base`` (or a new document) with ``surfaces`` appended; a base surface on the same
    hindfoot body is replaced."""
    if base is None:
        return OsimxModel(name=model_name, associated_osim_model=model_file, contact_surfaces=tuple(surfaces))
    bodies = {s.hindfoot_body for s in surfaces}
    kept = tuple(s for s in base.contact_surfaces if s.hindfoot_body not in bodies)
    return attrs.evolve(base, contact_surfaces=kept + tuple(surfaces))


def write_foot_files(stage: Path, prefix: str, foot: FootInputs, values: FootValues, state: GcpState) -> None:
    """The four per-foot tables of the module docstring."""
    n = foot.index
    write_storage(stage / f"{prefix}_Foot_{n}_experimentalFootKinematics.sto", kinematics_table(foot, foot.coordinates))
    write_storage(stage / f"{prefix}_Foot_{n}_optimizedFootKinematics.sto",
                  kinematics_table(foot, as_array(values.coordinates).T))
    experimental_point, modeled_point = reference_points(foot, values, state.resting_spring_length)
    write_storage(stage / f"{prefix}_Foot_{n}_replacedExperimentalGroundReactions.sto",
                  reactions_table(foot.time, as_array(values.experimental_forces).T,
                                  as_array(values.experimental_moments).T, experimental_point))
    write_storage(stage / f"{prefix}_Foot_{n}_optimizedGroundReactions.sto",
                  reactions_table(foot.time, as_array(values.forces).T, as_array(values.moments).T, modeled_point))


def same_window(feet: Sequence[FootInputs]) -> bool:
    """True when every foot has the same frames (combined GRF/IK files are written then)."""
    first = feet[0].time
    return all(f.time.shape == first.shape and np.allclose(f.time, first, atol=1e-9) for f in feet)


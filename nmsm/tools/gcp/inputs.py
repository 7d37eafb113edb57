"""Everything GCP needs per foot before optimizing: the foot model, its springs, the
experimental kinematics and ground reactions on the foot's window, the B-spline bases of
the kinematic deviation and the per-frame CasADi function of the contact model.

Per foot (``T`` frames, ``n`` springs, ``m`` B-spline nodes):

* ``coordinates`` (T, 7): experimental foot coordinates (rad, m), see
  :mod:`nmsm.tools.gcp.foot_model`; ``markers`` (T, 5, 3) m and ``marker_velocities``
  (T, 5, 3) m/s of the foot markers (roles in :data:`~nmsm.tools.gcp.foot_model.MARKER_ROLES`
  order); ``midfoot`` (T, 3) m the experimental midfoot-superior marker.
* ``basis``/``basis_rate`` (T, m): degree-4 B-spline values and time derivatives (1/s);
  ``base_nodes`` (m, 7) the least-squares fit of ``coordinates``. Modeled coordinates are
  ``basis @ (base_nodes * C)`` with the multiplicative coefficients ``C`` (m, 7).
* ``slope_experimental``/``slope_modeled`` (T, T): the degree-2 B-spline derivative
  operators of the slope terms (``m`` nodes for experimental, 25 for modeled curves).
* ``frame_function``: ``(q 7, qdot 7, parameters 6) -> (markers 3x5, marker velocities
  3x5, loads_per_k 6xn, loads_offset 6x1, spring positions 3xn)`` for one frame: the
  ground reaction and its moment about the modeled midfoot-superior marker projected on
  the floor are ``loads_per_k @ K + loads_offset``
  (:func:`~nmsm.model.foot_contact.unit_loads`).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.osimx import OsimxContactSurface, OsimxModel
from nmsm.io.settings.gcp import ContactSurfaceSettings, GroundContactPersonalizationSettings, surface_label
from nmsm.io.storage import Table
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.components import Model
from nmsm.model.foot_contact import unit_loads
from nmsm.tools.gcp import bspline
from nmsm.tools.gcp.data import (GroundReactions, foot_ground_reactions, full_coordinates, window_indices)
from nmsm.tools.gcp.foot_model import FootMarkers, FootModel, foot_coordinates, unwrap_angles
from nmsm.tools.gcp.spring_grid import SpringLayout, layout_from_osimx, place_springs

#: B-spline degree of the foot kinematics
KINEMATICS_DEGREE = 4
#: B-spline degree of the slope terms' derivatives
SLOPE_DEGREE = 2
#: node count of the modeled curves' slope derivative
MODELED_SLOPE_NODES = 25


@attrs.define(eq=False)
class FootInputs:
    """One foot's fixed inputs (module docstring)."""

    index: int
    surface: ContactSurfaceSettings
    foot: FootModel
    springs: SpringLayout
    time: np.ndarray
    coordinates: np.ndarray
    markers: np.ndarray
    marker_velocities: np.ndarray
    midfoot: np.ndarray
    reactions: GroundReactions
    basis: np.ndarray
    basis_rate: np.ndarray
    base_nodes: np.ndarray
    slope_experimental: np.ndarray
    slope_modeled: np.ndarray
    frame_function: cs.Function

    @property
    def n_frames(self) -> int:
        return int(self.time.size)

    @property
    def n_nodes(self) -> int:
        return int(self.base_nodes.shape[0])

    @property
    def plate_moments_about_midfoot(self) -> np.ndarray:
        """Plate moments (T, 3) N m moved to the experimental midfoot point projected on the
        floor (height 0): ``M + (EC - (x_ms, 0, z_ms)) x F``."""
        point = self.midfoot.copy()
        point[:, 1] = 0.0
        r = self.reactions
        return r.moments + np.cross(r.electrical_center - point, r.forces)


def foot_markers(surface: ContactSurfaceSettings) -> FootMarkers:
    return FootMarkers(surface.toe_marker, surface.medial_marker, surface.lateral_marker, surface.heel_marker,
                       surface.midfoot_superior_marker)


def build_frame_function(foot: FootModel, springs: SpringLayout) -> cs.Function:
    """The per-frame function described in the module docstring."""
    q, qdot = foot.q, foot.qdot
    marker_positions = foot.point_positions(foot.marker_points)
    marker_velocities = foot.point_velocities(marker_positions)
    spring_positions = foot.point_positions(springs.points())
    spring_velocities = foot.point_velocities(spring_positions)
    parameters = cs.SX.sym("parameters", 6)
    midfoot = marker_positions[:, 4]
    reference = cs.vertcat(midfoot[0], 0, midfoot[2])
    per_k, offset = unit_loads(spring_positions, spring_velocities, parameters, reference)
    return cs.Function("gcp_frame", [q, qdot, parameters],
                       [marker_positions, marker_velocities, per_k, offset, spring_positions],
                       ["q", "qdot", "parameters"],
                       ["markers", "marker_velocities", "loads_per_k", "loads_offset", "spring_positions"])


def experimental_foot_coordinates(casadi_model: CasadiModel, q_full: np.ndarray, foot: FootModel) -> np.ndarray:
    """Foot coordinates (T, 7) from full-model coordinates ``q_full`` (T, n)."""
    pose = casadi_model.body_pose_function(foot.hindfoot_body)
    toe_index = casadi_model.coordinate_index(foot.toe_coordinate)
    rows = []
    for q in q_full:
        rotation, origin = pose(q)
        rows.append(foot_coordinates(np.array(rotation), np.array(origin).ravel(), q[toe_index], foot.is_left))
    return unwrap_angles(np.array(rows))


def default_origin_height(casadi_model: CasadiModel, body: str) -> float:
    """Height (m) of ``body``'s origin in the model's default pose."""
    q = np.array([c.default_value for c in casadi_model.model.coordinates])
    _, origin = casadi_model.body_pose_function(body)(q)
    return float(np.array(origin).ravel()[1])


def matching_osimx_surface(osimx: OsimxModel | None, surface: ContactSurfaceSettings) -> OsimxContactSurface | None:
    """The input ``.osimx`` surface on the same hindfoot body, if any."""
    if osimx is None:
        return None
    for candidate in osimx.contact_surfaces:
        if candidate.hindfoot_body == surface.hindfoot_body and candidate.springs:
            return candidate
    return None


def surface_foot_model(index: int, surface: ContactSurfaceSettings, model: Model,
                       settings_file: Path | None) -> FootModel:
    """The :class:`FootModel` of one surface; a body or marker the model lacks is an
    :class:`InputError` (:class:`ModelError` for the model's structure) at the surface's line of the
    settings file, naming the model."""
    try:
        return FootModel(model, surface.hindfoot_body, foot_markers(surface), surface.is_left_foot)
    except InputError as exc:
        raise type(exc)(f"{exc.detail} (model {model.file})", file=settings_file, line=surface.source.line,
                         element=f"{surface_label(surface, index)}: {exc.element}", expected=exc.expected) from None


def build_foot_inputs(index: int, surface: ContactSurfaceSettings, settings: GroundContactPersonalizationSettings,
                      model: Model, casadi_model: CasadiModel, motion: Table, grf: Table,
                      osimx: OsimxModel | None, *, spring_source: Path | None = None) -> FootInputs:
    """The :class:`FootInputs` of one enabled contact surface (foot ``index``, 1-based)."""
    settings_file = str(settings.settings_file) if settings.settings_file else None
    foot = surface_foot_model(index, surface, model, settings.settings_file)
    rows = window_indices(motion.time, surface.start_time, surface.end_time, file=settings.input_motion_file,
                          element=f"<GCPContactSurface> {surface.name or index}",
                          settings_file=settings.settings_file)
    time = motion.time[rows]
    q_full = full_coordinates(motion, model, rows, foot.hindfoot_body, motion_file=settings.input_motion_file)
    coordinates = experimental_foot_coordinates(casadi_model, q_full, foot)
    reactions = foot_ground_reactions(
        grf, time, surface.force_columns, surface.moment_columns, surface.electrical_center_columns,
        grf_file=settings.input_grf_file, motion_file=settings.input_motion_file,
        settings_file=settings.settings_file, line=surface.source.line, surface=surface_label(surface, index))
    existing = matching_osimx_surface(osimx, surface)
    if existing is not None:
        springs = layout_from_osimx(existing.springs, foot, source=str(spring_source) if spring_source else None)
    else:
        height = -default_origin_height(casadi_model, foot.hindfoot_body)
        springs = place_springs(foot, settings.grid_width, settings.grid_height, spring_height=height,
                                settings_file=settings_file)
    interval = float(np.mean(np.diff(time)))
    try:
        n_nodes = bspline.nodes_for_cutoff(time, coordinates, settings.kinematics_filter_cutoff, KINEMATICS_DEGREE)
    except InputError as exc:  # a sampling rate rounding to 0 Hz: name the motion file
        if exc.file is not None:
            raise
        raise InputError(exc.detail, file=settings.input_motion_file, element=exc.element,
                         expected=exc.expected) from exc
    basis, basis_rate, _ = bspline.bspline_matrices(KINEMATICS_DEGREE, n_nodes, time.size, interval)
    base_nodes = bspline.fit_nodes(basis, coordinates)
    markers_fn = foot.marker_function()
    base_rates = basis_rate @ base_nodes
    fitted = basis @ base_nodes
    markers = np.zeros((time.size, 5, 3))
    marker_velocities = np.zeros((time.size, 5, 3))
    for t in range(time.size):
        markers[t] = np.array(markers_fn(coordinates[t], np.zeros(7))[0]).T
        marker_velocities[t] = np.array(markers_fn(fitted[t], base_rates[t])[1]).T
    slope_nodes = min(n_nodes, time.size)
    return FootInputs(
        index=index,
        surface=surface,
        foot=foot,
        springs=springs,
        time=time,
        coordinates=coordinates,
        markers=markers,
        marker_velocities=marker_velocities,
        midfoot=markers[:, 4, :].copy(),
        reactions=reactions,
        basis=basis,
        basis_rate=basis_rate,
        base_nodes=base_nodes,
        slope_experimental=bspline.derivative_matrix(time, SLOPE_DEGREE, slope_nodes),
        slope_modeled=bspline.derivative_matrix(time, SLOPE_DEGREE, min(MODELED_SLOPE_NODES, time.size)),
        frame_function=build_frame_function(foot, springs),
    )


def check_equal_spring_counts(feet: list[FootInputs], settings_file: Path | None) -> None:
    """Feet optimized together share spring constants: their spring counts must match."""
    counts = {f.index: f.springs.n_springs for f in feet}
    if len(set(counts.values())) > 1:
        detail = ", ".join(f"foot {k}: {v}" for k, v in counts.items())
        raise InputError(f"feet optimized together need the same number of springs ({detail})",
                         file=settings_file, element="<GCPContactSurfaceSet>",
                         expected="equal spring counts (same grid), or run the feet separately")
    if len(feet) > 1 and len({f.springs.bodies.count(f.foot.toes_body) for f in feet}) > 1:
        warnings.warn("feet optimized together have different numbers of toes springs; spring constants are "
                      "shared by index", stacklevel=2)

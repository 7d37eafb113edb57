"""The two-segment foot GCP works on, extracted from a full- or lower-body model.

The foot is the hindfoot body, the toes body and the toes joint between them (the one
child joint of the hindfoot with one coordinate), moved by a six-coordinate joint to
ground. Its coordinate vector is::

    q = [toe, r1, r2, r3, tx, ty, tz]      (rad, rad, rad, rad, m, m, m)

with the hindfoot orientation ``R = Ry(r1) Rx(r2) Rz(r3)`` (left foot:
``R = R(-y, r1) R(-x, r2) Rz(r3)``, the mirrored joint) and its origin ``(tx, ty, tz)``
in ground. :func:`foot_coordinates` gives these values from the body's pose in the
full model, so the foot reproduces the full model's hindfoot and toes exactly.

Point functions are SX Functions of one frame; velocities are the exact time derivatives
``J(q) qdot`` of the positions (the foot's speeds are its coordinate rates).
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import InputError, ModelError
from nmsm.model.components import Model
from nmsm.model.foot_contact import toes_body_of
from nmsm.model.joint_motion import joint_pose
from nmsm.model.kinematics import TreeKinematics
from nmsm.model.spatial import axis_angle

#: names of the seven foot coordinates, in order
FOOT_COORDINATES = ("toe", "Rotation1", "Rotation2", "Rotation3", "Translation1", "Translation2", "Translation3")
#: marker roles of a contact surface, in the order markers are stacked
MARKER_ROLES = ("toe", "medial", "lateral", "heel", "midfoot_superior")


@attrs.frozen
class FootMarkers:
    """Marker names of one foot by role (settings ``<*_marker>`` elements)."""

    toe: str
    medial: str
    lateral: str
    heel: str
    midfoot_superior: str

    def names(self) -> tuple[str, ...]:
        return tuple(getattr(self, role) for role in MARKER_ROLES)


def _rotation_axes(is_left: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    sign = -1.0 if is_left else 1.0
    return np.array([0.0, sign, 0.0]), np.array([sign, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])


class FootModel:
    """Kinematics of one two-segment foot (see module docstring).

    ``points`` are given as ``(body, location)`` pairs, ``body`` the hindfoot or toes body
    and ``location`` (3,) m in that body's frame (as in the ``.osim`` file).
    """

    def __init__(self, model: Model, hindfoot_body: str, markers: FootMarkers, is_left: bool,
                 *, settings_file: str | None = None) -> None:
        self.model = model
        self.hindfoot_body = hindfoot_body
        self.toes_body = toes_body_of(model, hindfoot_body)
        self.toes_joint = next(j for j in model.joints if j.parent_body == hindfoot_body and j.child_body == self.toes_body)
        self.toe_coordinate = self.toes_joint.coordinates[0]
        self.is_left = is_left
        self.markers = markers
        self._kinematics = TreeKinematics(model)
        self.q = cs.SX.sym("q", 7)
        self.qdot = cs.SX.sym("qdot", 7)
        self.marker_points = self._marker_points(settings_file)

    # ------------------------------------------------------------------ geometry
    def _marker_points(self, settings_file: str | None) -> list[tuple[str, np.ndarray]]:
        index = {m.name: i for i, m in enumerate(self.model.markers)}
        points = []
        for role, name in zip(MARKER_ROLES, self.markers.names()):
            if name not in index:
                raise InputError(f"the model has no marker '{name}' ({role} marker of the foot on "
                                 f"'{self.hindfoot_body}')", file=settings_file, element=f"<{role}_marker>",
                                 expected=f"a marker of {self.model.file} on '{self.hindfoot_body}' or "
                                          f"'{self.toes_body}'" + self._other_side_hint(name, index))
            marker = self.model.markers[index[name]]
            if marker.body not in (self.hindfoot_body, self.toes_body):
                raise InputError(f"marker '{name}' ({role}) is on body '{marker.body}'", file=settings_file,
                                 element=f"<{role}_marker>",
                                 expected=f"a marker on '{self.hindfoot_body}' or '{self.toes_body}'")
            location = np.array(self._kinematics.marker_in_body(index[name])).ravel()
            points.append((marker.body, location))
        return points

    def _other_side_hint(self, name: str, index: dict[str, int]) -> str:
        """How to add a missing marker whose other-side twin the model has (``L_Toe_Medial``
        for ``R_Toe_Medial``), else ''."""
        for twin in other_side_names(name):
            if twin in index:
                body = self.model.markers[index[twin]].body
                return (f"; the model has '{twin}' on '{body}': add '{name}' to the model on this foot's body at "
                        f"its mirror image (z negated)")
        return ""

    def toes_pose_in_hindfoot(self, toe_angle: object) -> tuple[cs.SX, cs.SX]:
        """``(R, p)``: orientation and origin of the toes frame in the hindfoot frame."""
        r_pf, p_pf = self._kinematics.frame_in_base(self.toes_joint.parent_frame)
        r_cm, p_cm = self._kinematics.frame_in_base(self.toes_joint.child_frame)
        angle = cs.SX(toe_angle) if not isinstance(toe_angle, cs.SX) else toe_angle
        r_fm, p_fm = joint_pose(self.toes_joint, cs.vertcat(angle), 1.0)
        rotation = cs.mtimes([r_pf, r_fm, r_cm.T])
        origin = p_pf + cs.mtimes(r_pf, p_fm) - cs.mtimes(rotation, p_cm)
        return rotation, origin

    def hindfoot_pose(self, q: cs.SX) -> tuple[cs.SX, cs.SX]:
        """``(R, p)`` of the hindfoot in ground at foot coordinates ``q`` (7,)."""
        a1, a2, a3 = _rotation_axes(self.is_left)
        rotation = cs.mtimes([axis_angle(a1, q[1]), axis_angle(a2, q[2]), axis_angle(a3, q[3])])
        return rotation, q[4:7]

    def body_poses(self, q: cs.SX) -> dict[str, tuple[cs.SX, cs.SX]]:
        """Poses in ground of the hindfoot and toes bodies at ``q``."""
        r_h, p_h = self.hindfoot_pose(q)
        r_t, p_t = self.toes_pose_in_hindfoot(q[0])
        return {self.hindfoot_body: (r_h, p_h), self.toes_body: (cs.mtimes(r_h, r_t), p_h + cs.mtimes(r_h, p_t))}

    def point_positions(self, points: Sequence[tuple[str, np.ndarray]], q: cs.SX | None = None) -> cs.SX:
        """Ground positions (3, k) of ``points`` at ``q`` (default: the model's symbol)."""
        q = self.q if q is None else q
        poses = self.body_poses(q)
        columns = []
        for body, location in points:
            if body not in poses:
                raise ModelError(f"point on body '{body}'", file=self.model.file,
                                 expected=f"a point on '{self.hindfoot_body}' or '{self.toes_body}'")
            rotation, origin = poses[body]
            columns.append(origin + cs.mtimes(rotation, cs.DM(np.asarray(location, dtype=float))))
        return cs.horzcat(*columns) if columns else cs.SX(3, 0)

    def point_velocities(self, positions: cs.SX) -> cs.SX:
        """Time derivatives (3, k) of ``positions`` (built from :attr:`q`) at rates :attr:`qdot`."""
        return cs.reshape(cs.jtimes(cs.vec(positions), self.q, self.qdot), 3, -1)

    def points_function(self, points: Sequence[tuple[str, np.ndarray]], name: str = "foot_points") -> cs.Function:
        """``(q, qdot) -> (positions 3 x k, velocities 3 x k)`` of ``points`` (m, m/s, ground)."""
        positions = self.point_positions(points)
        return cs.Function(name, [self.q, self.qdot], [positions, self.point_velocities(positions)],
                           ["q", "qdot"], ["positions", "velocities"])

    def marker_function(self) -> cs.Function:
        """``(q, qdot) -> (positions 3 x 5, velocities 3 x 5)`` of the foot markers in
        :data:`MARKER_ROLES` order."""
        return self.points_function(self.marker_points, "foot_markers")

    def points_in_hindfoot(self, points: Sequence[tuple[str, np.ndarray]], toe_angle: float = 0.0) -> np.ndarray:
        """Locations (k, 3) m of ``points`` in the hindfoot frame with the toes at ``toe_angle``."""
        r_t, p_t = self.toes_pose_in_hindfoot(toe_angle)
        r_t, p_t = np.array(cs.DM(r_t)), np.array(cs.DM(p_t)).ravel()
        out = []
        for body, location in points:
            loc = np.asarray(location, dtype=float)
            out.append(loc if body == self.hindfoot_body else p_t + r_t @ loc)
        return np.array(out).reshape(-1, 3)

    def hindfoot_to_toes(self, location: np.ndarray, toe_angle: float = 0.0) -> np.ndarray:
        """A hindfoot-frame location (3,) m expressed in the toes frame (toes at ``toe_angle``)."""
        r_t, p_t = self.toes_pose_in_hindfoot(toe_angle)
        r_t, p_t = np.array(cs.DM(r_t)), np.array(cs.DM(p_t)).ravel()
        return r_t.T @ (np.asarray(location, dtype=float) - p_t)

    def toe_axis_in_hindfoot(self) -> tuple[np.ndarray, np.ndarray]:
        """``(point, direction)`` of the toes joint axis in the hindfoot frame (m, unit)."""
        r_pf, p_pf = self._kinematics.frame_in_base(self.toes_joint.parent_frame)
        r_pf, p_pf = np.array(r_pf), np.array(p_pf).ravel()
        if self.toes_joint.type == "CustomJoint":
            axis = next((a.axis for a in self.toes_joint.transform_axes[:3] if a.coordinates), np.array([0, 0, 1.0]))
        else:
            axis = np.array([0.0, 0.0, 1.0])
        direction = r_pf @ (np.asarray(axis, dtype=float) / np.linalg.norm(axis))
        return p_pf, direction


def yxz_angles(rotation: np.ndarray) -> np.ndarray:
    """Angles ``(a, b, c)`` (rad) with ``rotation = Ry(a) Rx(b) Rz(c)``; ``b`` in [-pi/2, pi/2]."""
    r = np.asarray(rotation, dtype=float)
    b = np.arcsin(np.clip(-r[1, 2], -1.0, 1.0))
    a = np.arctan2(r[0, 2], r[2, 2])
    c = np.arctan2(r[1, 0], r[1, 1])
    return np.array([a, b, c])


_SIDE_PREFIX_SWAPS = (("R_", "L_"), ("L_", "R_"), ("r_", "l_"), ("l_", "r_"))
_SIDE_SUFFIX_SWAPS = (("_r", "_l"), ("_l", "_r"), ("_R", "_L"), ("_L", "_R"))


def other_side_names(name: str) -> list[str]:
    """The other foot's spellings of a marker name (``R_Heel`` -> ``L_Heel``, ``heel_r`` ->
    ``heel_l``)."""
    out = [other + name[len(side):] for side, other in _SIDE_PREFIX_SWAPS if name.startswith(side)]
    return out + [name[: -len(side)] + other for side, other in _SIDE_SUFFIX_SWAPS if name.endswith(side)]


def foot_coordinates(rotation: np.ndarray, origin: np.ndarray, toe_angle: float, is_left: bool) -> np.ndarray:
    """The foot coordinates (7,) of a hindfoot with orientation ``rotation`` (3, 3, body to
    ground) and ``origin`` (3,) m, toes at ``toe_angle`` rad (module docstring)."""
    a, b, c = yxz_angles(rotation)
    if is_left:
        a, b = -a, -b
    return np.concatenate([[toe_angle, a, b, c], np.asarray(origin, dtype=float).ravel()])


def unwrap_angles(q: np.ndarray) -> np.ndarray:
    """Foot coordinates (T, 7) with the three hindfoot angles unwrapped along time."""
    out = np.array(q, dtype=float, copy=True)
    out[:, 1:4] = np.unwrap(out[:, 1:4], axis=0)
    return out

"""Forward kinematics of the joint tree as CasADi SX expressions.

:class:`TreeKinematics` walks the joints in tree order and returns, for every body, its
pose in ground and (when speeds and accelerations are given) its angular velocity and
acceleration and the velocity and acceleration of its origin, all expressed in ground:

    R (3x3, body -> ground), p (3, m), w (3, rad/s), v (3, m/s), alpha (3, rad/s^2), a (3, m/s^2)

Inputs are the full coordinate vector ``q`` (model coordinate order, dependent
coordinates included), speeds ``u`` and their rates; model parameters
(:class:`~nmsm.model.parameters.ModelParameters`) enter wherever registered.
"""

from __future__ import annotations

from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import ModelError
from nmsm.model.components import GROUND, Model
from nmsm.model.joint_motion import joint_motion_function
from nmsm.model.parameters import ModelParameters
from nmsm.model.spatial import body_xyz


@attrs.define
class BodyState:
    """Pose and motion of a body frame in ground (see module docstring)."""

    R: Any
    p: Any
    w: Any = None
    v: Any = None
    alpha: Any = None
    a: Any = None


class TreeKinematics:
    """Kinematics of ``model`` with optional symbolic ``parameters`` (SX expressions)."""

    def __init__(self, model: Model, parameters: ModelParameters | None = None,
                 custom_joint_bias: str = "opensim") -> None:
        self.model = model
        self.parameters = parameters if parameters is not None else ModelParameters(model)
        names = model.coordinate_names
        self.coordinate_index = {name: i for i, name in enumerate(names)}
        self.n = len(names)
        self.joint_indices = [[self.coordinate_index[c] for c in j.coordinates] for j in model.joints]
        self.motions = [joint_motion_function(j, custom_joint_bias) for j in model.joints]
        self._frame_cache: dict[str, tuple[Any, Any]] = {}

    # ------------------------------------------------------------------ parameters
    def scale(self, body: str) -> Any:
        """Uniform scale factor of ``body`` (1.0 unless parameterized)."""
        return self.parameters.scales.get(body, 1.0)

    def frame_in_base(self, frame_path: str) -> tuple[Any, Any]:
        """``(R, p)`` of a frame in its base body (parameters and scale applied)."""
        cached = self._frame_cache.get(frame_path)
        if cached is not None:
            return cached
        frame = self.model.frames.get(frame_path)
        if frame is None:
            raise ModelError(f"no frame '{frame_path}'", file=self.model.file, expected="a frame of the model")
        if frame.kind != "offset":
            result = (cs.DM.eye(3), cs.DM.zeros(3, 1))
        else:
            parent_r, parent_p = self.frame_in_base(frame.parent)
            orientation = self.parameters.orientations.get(frame_path)
            translation = self.parameters.translations.get(frame_path)
            rotation = cs.DM(_rotation_numeric(frame.orientation)) if orientation is None else body_xyz(orientation)
            translation = cs.DM(frame.translation) if translation is None else translation
            translation = translation * self.scale(frame.base_body)
            result = (cs.mtimes(parent_r, rotation), parent_p + cs.mtimes(parent_r, translation))
        self._frame_cache[frame_path] = result
        return result

    def local_point(self, frame_path: str, point: Any) -> Any:
        """A point given in a frame (file geometry) -> coordinates in the base body, scaled."""
        r, p = self.frame_in_base(frame_path)
        base = self.model.frames[frame_path].base_body
        return p + cs.mtimes(r, point * self.scale(base))

    def marker_in_body(self, index: int) -> Any:
        marker = self.model.markers[index]
        location = self.parameters.marker_locations.get(marker.name)
        location = cs.DM(marker.location) if location is None else location
        return self.local_point(marker.frame, location)

    def body_mass_properties(self, body: str) -> tuple[Any, Any, Any]:
        """``(mass, centre of mass in body, inertia about COM)`` with the body's scale applied."""
        b = self.model.bodies[body]
        s = self.scale(body)
        mass: Any = b.mass
        inertia: Any = cs.DM(b.inertia)
        if body in self.parameters.scales:
            if self.parameters.scale_mass:
                mass = b.mass * s**3
                inertia = inertia * s**5
            else:
                inertia = inertia * s**2
        return mass, cs.DM(b.mass_center) * s, inertia

    # ------------------------------------------------------------------ recursion
    def forward(self, q: Any, u: Any = None, udot: Any = None) -> dict[str, BodyState]:
        """Body states (ground frame) for coordinates ``q`` and, when given, speeds ``u`` and
        their rates ``udot`` (SX vectors of length n, model coordinate order). Gravity is
        not included in the accelerations."""
        with_velocity = u is not None
        with_acceleration = udot is not None
        zero3 = cs.DM.zeros(3, 1)
        states = {GROUND: BodyState(cs.DM.eye(3), zero3, zero3, zero3, zero3, zero3)}
        for joint, idx, motion in zip(self.model.joints, self.joint_indices, self.motions):
            parent = states[joint.parent_body]
            r_pf, p_pf = self.frame_in_base(joint.parent_frame)
            r_cm, p_cm = self.frame_in_base(joint.child_frame)
            qj = _take(q, idx)
            uj = _take(u, idx) if with_velocity else cs.DM.zeros(len(idx), 1)
            r_fm, p_fm, h_w, h_v, c_w, c_v = motion(qj, uj, self.scale(joint.parent_body))
            r_gf = cs.mtimes(parent.R, r_pf)
            r_f = cs.mtimes(parent.R, p_pf)  # parent origin -> F origin
            o_f = parent.p + r_f
            d = cs.mtimes(r_gf, p_fm)  # F origin -> M origin
            o_m = o_f + d
            r_gc = cs.mtimes(cs.mtimes(r_gf, r_fm), r_cm.T)
            s_vec = -cs.mtimes(r_gc, p_cm)  # M origin -> child origin
            state = BodyState(r_gc, o_m + s_vec)
            if with_velocity:
                w_rel = cs.mtimes(r_gf, cs.mtimes(h_w, uj)) if idx else zero3
                v_rel = cs.mtimes(r_gf, cs.mtimes(h_v, uj)) if idx else zero3
                state.w = parent.w + w_rel
                v_om = parent.v + cs.cross(parent.w, r_f + d) + v_rel
                state.v = v_om + cs.cross(state.w, s_vec)
                if with_acceleration:
                    udj = _take(udot, idx)
                    a_rel = cs.mtimes(r_gf, cs.mtimes(h_w, udj) + c_w) if idx else zero3
                    l_rel = cs.mtimes(r_gf, cs.mtimes(h_v, udj) + c_v) if idx else zero3
                    state.alpha = parent.alpha + a_rel + cs.cross(parent.w, w_rel)
                    r_pm = r_f + d
                    a_om = (parent.a + cs.cross(parent.alpha, r_pm)
                            + cs.cross(parent.w, cs.cross(parent.w, r_pm))
                            + 2 * cs.cross(parent.w, v_rel) + l_rel)
                    state.a = a_om + cs.cross(state.alpha, s_vec) + cs.cross(state.w, cs.cross(state.w, s_vec))
            states[joint.child_body] = state
        return states


def _take(vector: Any, indices: list[int]) -> Any:
    if not indices:
        return cs.DM.zeros(0, 1)
    return cs.vertcat(*[vector[i] for i in indices])


def _rotation_numeric(angles: np.ndarray) -> np.ndarray:
    from nmsm.model.rotations import body_xyz as numeric_body_xyz

    return numeric_body_xyz(angles)

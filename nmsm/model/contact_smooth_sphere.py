"""OpenSim's SmoothSphereHalfSpaceForce in CasADi (smooth Hunt-Crossley normal force with
smooth Stribeck/viscous friction; Serrancoli et al. 2019, as implemented in Simbody).

With the half space's normal ``n`` (its frame's +x axis, in ground, pointing into the
half space), sphere centre ``c`` and radius ``r``:

    indentation  d  = (c - o_halfspace) . n + r
    contact point P = c + r n - d/2 n
    v = velocity of P on the sphere body - velocity of P on the half-space body
    v_n = v . n,  v_t = v - v_n n
    k = stiffness^(2/3) / 2
    F_hertz = 4/3 k sqrt(r k) (d^2 + cf)^(3/4) (1/2 + tanh(b_d d)/2)
    F_n = F_hertz (1 + 3/2 c_d v_n) (1/2 + tanh(b_v (v_n + 2/(3 c_d)))/2)
    v_s = sqrt(|v_t|^2 + cf),  v_r = v_s / v_transition
    F_f = F_n (min(v_r, 1) (mu_d + 2 (mu_s - mu_d) / (1 + v_r^2)) + mu_v v_s)
    force on the sphere body at P: -(F_n n + F_f v_t / v_s)   (the opposite on the half space)

Forces in N, lengths in m, velocities in m/s.
"""

from __future__ import annotations

from typing import Any

import attrs
import casadi as cs

from nmsm.model.components import SmoothSphereHalfSpaceForce
from nmsm.model.kinematics import BodyState, TreeKinematics
from nmsm.model.spatial import body_xyz


@attrs.define
class ContactResult:
    """One contact force: ``force`` (N, ground) acting on ``sphere_body`` at ``point``
    (m, ground); the half-space body ``half_space_body`` receives ``-force`` there."""

    name: str
    sphere_body: str
    half_space_body: str
    force: Any
    point: Any
    indentation: Any


def contact_force(kin: TreeKinematics, element: SmoothSphereHalfSpaceForce,
                  states: dict[str, BodyState]) -> ContactResult:
    """The contact force of ``element`` for body states with velocities (SX)."""
    model = kin.model
    sphere = model.contact_geometry[element.sphere]
    plane = model.contact_geometry[element.half_space]
    s_state = states[sphere.body]
    h_state = states[plane.body]
    centre_local = kin.local_point(sphere.frame, cs.DM(sphere.location))
    centre = s_state.p + cs.mtimes(s_state.R, centre_local)
    r_frame, p_frame = kin.frame_in_base(plane.frame)
    plane_rotation = cs.mtimes(r_frame, body_xyz(cs.DM(plane.orientation)))
    plane_origin_local = kin.local_point(plane.frame, cs.DM(plane.location))
    normal = cs.mtimes(h_state.R, plane_rotation[:, 0])
    plane_origin = h_state.p + cs.mtimes(h_state.R, plane_origin_local)
    radius = sphere.radius
    depth = cs.dot(centre - plane_origin, normal) + radius
    point = centre + radius * normal - 0.5 * depth * normal
    v1 = s_state.v + cs.cross(s_state.w, point - s_state.p)
    v2 = h_state.v + cs.cross(h_state.w, point - h_state.p)
    v = v1 - v2
    v_normal = cs.dot(v, normal)
    v_tangent = v - v_normal * normal
    e = element
    k = 0.5 * e.stiffness ** (2.0 / 3.0)
    hertz = (4.0 / 3.0) * k * (radius * k) ** 0.5 * (depth**2 + e.constant_contact_force) ** 0.75
    hertz = hertz * (0.5 + 0.5 * cs.tanh(e.hertz_smoothing * depth))
    normal_force = hertz * (1 + 1.5 * e.dissipation * v_normal)
    if e.dissipation != 0.0:
        normal_force = normal_force * (0.5 + 0.5 * cs.tanh(e.hunt_crossley_smoothing
                                                           * (v_normal + 2.0 / (3.0 * e.dissipation))))
    slip = cs.sqrt(cs.sumsqr(v_tangent) + e.constant_contact_force)
    relative = slip / e.transition_velocity
    friction = normal_force * (cs.fmin(relative, 1.0) * (e.dynamic_friction + 2 * (e.static_friction - e.dynamic_friction)
                                                         / (1 + relative**2)) + e.viscous_friction * slip)
    on_plane = normal_force * normal + friction * v_tangent / slip
    return ContactResult(e.name, sphere.body, plane.body, -on_plane, point, depth)

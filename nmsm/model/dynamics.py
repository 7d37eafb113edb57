"""Inverse dynamics by the recursive Newton-Euler method over the joint tree (SX).

:func:`inverse_dynamics` returns the generalized forces (N m for rotational, N for
translational coordinates; model coordinate order, one per coordinate, dependent ones
included) that produce the accelerations ``udot`` at state ``(q, u)`` under gravity,
given external loads. Constraints are ignored, as in OpenSim's inverse dynamics:

    tau = M(q) udot + C(q, u) - G(q) - J(q)^T F_ext - tau_applied

The recursion works in body frames (each body's velocities, accelerations and forces
are expressed in its own frame, so inertias stay constant and each step depends only on
one joint's coordinates: small expressions and cheap derivatives). Gravity enters as an
upward acceleration of ground. External loads are :class:`GroundLoad` entries: a force
(N) applied at a point (m) and a pure torque (N m), all expressed in ground, on a named
body (for instance a ground reaction force on ``calcn_r`` at the centre of pressure).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs

from nmsm.model.components import GROUND
from nmsm.model.kinematics import TreeKinematics


@attrs.define
class GroundLoad:
    """A load on ``body``: ``force`` (N) at ``point`` (m) plus ``torque`` (N m), in ground."""

    body: str
    force: Any
    point: Any
    torque: Any


@attrs.define
class _Local:
    """A body's motion in its own frame: angular velocity/acceleration, velocity and
    acceleration (gravity included) of its origin."""

    w: Any
    alpha: Any
    v: Any
    a: Any


def inverse_dynamics(kin: TreeKinematics, q: Any, u: Any, udot: Any, loads: Sequence[GroundLoad] = (),
                     generalized_forces: Any = None, gravity: bool = True) -> Any:
    """Generalized forces (SX, ``(n, 1)``) for the motion ``(q, u, udot)`` (SX vectors)."""
    model = kin.model
    zero3 = cs.DM.zeros(3, 1)
    g = cs.DM(model.gravity) if gravity else zero3
    motion: dict[str, _Local] = {GROUND: _Local(zero3, zero3, zero3, -g)}
    joint_data = []
    for joint, idx, motion_f in zip(model.joints, kin.joint_indices, kin.motions):
        parent = motion[joint.parent_body]
        r_pf, p_pf = kin.frame_in_base(joint.parent_frame)
        r_cm, p_cm = kin.frame_in_base(joint.child_frame)
        qj = _take(q, idx)
        uj = _take(u, idx)
        udj = _take(udot, idx)
        r_fm, p_fm, h_w, h_v, c_w, c_v = motion_f(qj, uj, kin.scale(joint.parent_body))
        r_pc = cs.mtimes(cs.mtimes(r_pf, r_fm), r_cm.T)
        r_pm = p_pf + cs.mtimes(r_pf, p_fm)  # parent origin -> M origin (parent frame)
        s = -cs.mtimes(r_pc, p_cm)  # M origin -> child origin (parent frame)
        if idx:
            w_rel = cs.mtimes(r_pf, cs.mtimes(h_w, uj))
            v_rel = cs.mtimes(r_pf, cs.mtimes(h_v, uj))
            a_w = cs.mtimes(r_pf, cs.mtimes(h_w, udj) + c_w)
            a_v = cs.mtimes(r_pf, cs.mtimes(h_v, udj) + c_v)
        else:
            w_rel = v_rel = a_w = a_v = zero3
        w = parent.w + w_rel
        alpha = parent.alpha + a_w + cs.cross(parent.w, w_rel)
        v_m = parent.v + cs.cross(parent.w, r_pm) + v_rel
        a_m = (parent.a + cs.cross(parent.alpha, r_pm) + cs.cross(parent.w, cs.cross(parent.w, r_pm))
               + 2 * cs.cross(parent.w, v_rel) + a_v)
        v_c = v_m + cs.cross(w, s)
        a_c = a_m + cs.cross(alpha, s) + cs.cross(w, cs.cross(w, s))
        to_child = r_pc.T
        motion[joint.child_body] = _Local(cs.mtimes(to_child, w), cs.mtimes(to_child, alpha),
                                          cs.mtimes(to_child, v_c), cs.mtimes(to_child, a_c))
        joint_data.append((joint, idx, r_pc, r_pm + s, s, r_pf, h_w, h_v))
    # net force and moment about the origin each body needs, in its own frame
    force: dict[str, Any] = {}
    moment: dict[str, Any] = {}
    for name in model.bodies:
        m = motion[name]
        mass, c, inertia = kin.body_mass_properties(name)
        a_com = m.a + cs.cross(m.alpha, c) + cs.cross(m.w, cs.cross(m.w, c))
        f = mass * a_com
        force[name] = f
        moment[name] = cs.mtimes(inertia, m.alpha) + cs.cross(m.w, cs.mtimes(inertia, m.w)) + cs.cross(c, f)
    loaded = [load for load in loads if load.body != GROUND]
    if loaded:
        poses = kin.forward(q)
        for load in loaded:
            pose = poses[load.body]
            force[load.body] = force[load.body] - cs.mtimes(pose.R.T, load.force)
            arm = cs.mtimes(pose.R.T, load.point - pose.p)
            local_force = cs.mtimes(pose.R.T, load.force)
            moment[load.body] = moment[load.body] - cs.mtimes(pose.R.T, load.torque) - cs.cross(arm, local_force)
    tau = [cs.SX(0)] * kin.n
    for joint, idx, r_pc, p_pc, s, r_pf, h_w, h_v in reversed(joint_data):
        child = joint.child_body
        f_parent = cs.mtimes(r_pc, force[child])  # in the parent frame
        n_origin = cs.mtimes(r_pc, moment[child])  # about the child origin, parent frame
        if idx:
            n_m = n_origin + cs.cross(s, f_parent)  # about the M origin
            gen = cs.mtimes(h_v.T, cs.mtimes(r_pf.T, f_parent)) + cs.mtimes(h_w.T, cs.mtimes(r_pf.T, n_m))
            for k, i in enumerate(idx):
                tau[i] = gen[k]
        parent = joint.parent_body
        if parent != GROUND:
            force[parent] = force[parent] + f_parent
            moment[parent] = moment[parent] + n_origin + cs.cross(p_pc, f_parent)
    result = cs.vertcat(*tau)
    if generalized_forces is not None:
        result = result - generalized_forces
    return result


def _take(vector: Any, indices: list[int]) -> Any:
    if not indices:
        return cs.DM.zeros(0, 1)
    return cs.vertcat(*[vector[i] for i in indices])

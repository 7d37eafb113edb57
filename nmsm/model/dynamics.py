"""Inverse dynamics by the recursive Newton-Euler method over the joint tree (SX).

:func:`inverse_dynamics` returns the generalized forces (N m for rotational, N for
translational coordinates; model coordinate order, one per coordinate, dependent ones
included) that produce the accelerations ``udot`` at state ``(q, u)`` under gravity,
given external loads. Constraints are ignored, as in OpenSim's inverse dynamics:

    tau = M(q) udot + C(q, u) - G(q) - J(q)^T F_ext - tau_applied

External loads are :class:`GroundLoad` entries: a force (N) applied at a point (m) and a
pure torque (N m), all expressed in ground, on a named body (for instance a ground
reaction force on ``calcn_r`` at the centre of pressure).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs

from nmsm.model.components import GROUND
from nmsm.model.kinematics import JointState, TreeKinematics


@attrs.define
class GroundLoad:
    """A load on ``body``: ``force`` (N) at ``point`` (m) plus ``torque`` (N m), in ground."""

    body: str
    force: Any
    point: Any
    torque: Any


def inverse_dynamics(kin: TreeKinematics, q: Any, u: Any, udot: Any, loads: Sequence[GroundLoad] = (),
                     generalized_forces: Any = None, gravity: bool = True) -> Any:
    """Generalized forces (SX, ``(n, 1)``) for the motion ``(q, u, udot)`` (SX vectors)."""
    model = kin.model
    joint_states: list[JointState] = []
    states = kin.forward(q, u, udot, joint_states)
    g = cs.DM(model.gravity) if gravity else cs.DM.zeros(3, 1)
    # net force (N) and moment about the body origin (N m) each body needs, in ground
    force: dict[str, Any] = {}
    moment: dict[str, Any] = {}
    for name in model.bodies:
        st = states[name]
        mass, com_local, inertia = kin.body_mass_properties(name)
        c = cs.mtimes(st.R, com_local)
        a_com = st.a + cs.cross(st.alpha, c) + cs.cross(st.w, cs.cross(st.w, c))
        f = mass * (a_com - g)
        inertia_g = cs.mtimes(cs.mtimes(st.R, inertia), st.R.T)
        n_com = cs.mtimes(inertia_g, st.alpha) + cs.cross(st.w, cs.mtimes(inertia_g, st.w))
        force[name] = f
        moment[name] = n_com + cs.cross(c, f)
    for load in loads:
        if load.body == GROUND:
            continue
        st = states[load.body]
        force[load.body] = force[load.body] - load.force
        moment[load.body] = moment[load.body] - load.torque - cs.cross(load.point - st.p, load.force)
    tau = [cs.SX(0)] * kin.n
    # backward pass: accumulate subtree resultants about each joint's M origin
    subtree_force = dict(force)
    subtree_moment_origin = dict(moment)  # about the body origin
    for joint, idx, js in reversed(list(zip(model.joints, kin.joint_indices, joint_states))):
        child = joint.child_body
        st = states[child]
        f_total = subtree_force[child]
        n_origin = subtree_moment_origin[child]
        n_m = n_origin + cs.cross(st.p - js.o_M, f_total)  # about M origin
        if idx:
            gen = cs.mtimes(js.H_v.T, cs.mtimes(js.R_GF.T, f_total)) + cs.mtimes(js.H_w.T, cs.mtimes(js.R_GF.T, n_m))
            for k, i in enumerate(idx):
                tau[i] = gen[k]
        parent = joint.parent_body
        if parent != GROUND:
            pp = states[parent].p
            subtree_force[parent] = subtree_force[parent] + f_total
            subtree_moment_origin[parent] = subtree_moment_origin[parent] + n_m + cs.cross(js.o_M - pp, f_total)
    result = cs.vertcat(*tau)
    if generalized_forces is not None:
        result = result - generalized_forces
    return result

"""The motion a joint allows, as CasADi SX functions of its own coordinates.

For a joint with ``k`` coordinates, :func:`joint_motion_function` returns an SX Function

    (q_j[k], u_j[k], s) -> (R_FM[3x3], p_FM[3], H_w[3xk], H_v[3xk], c_w[3], c_v[3])

* ``R_FM``, ``p_FM``: pose of the child frame M in the parent frame F (p in F, m).
* ``H_w``, ``H_v``: angular velocity of M in F and velocity of M's origin in F, both
  expressed in F, per unit generalized speed: ``w = H_w u``, ``v = H_v u``.
* ``c_w``, ``c_v``: the velocity-product terms: ``dw/dt = H_w udot + c_w`` (F-frame
  derivatives), likewise for ``v``.
* ``s``: the uniform scale factor of the parent frame's base body; it multiplies the
  translation functions of a CustomJoint other than pure coordinate axes (LinearFunction
  1, 0), as OpenSim's scaling does. (OpenSim multiplies by ``dot(axis, factors)``, which
  flips axes pointing in a negative direction; nmsm uses ``s``, the length scaling.)

Generalized speeds ``u`` equal the coordinate rates except for the rotational
coordinates of FreeJoint and BallJoint, whose speeds are OpenSim's: the angular
velocity of M in F expressed in F.
"""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.core.function_names import function_name
from nmsm.errors import ModelError
from nmsm.model.components import Joint
from nmsm.model.functions import LinearFunction, value_and_derivatives
from nmsm.model.spatial import axis_angle, body_xyz, vee

_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])

#: joints whose rotational speeds are angular velocities (not Euler-angle rates)
ANGULAR_VELOCITY_JOINTS = ("FreeJoint", "BallJoint")


def _is_coordinate_axis(axis) -> bool:
    f = axis.function
    return isinstance(f, LinearFunction) and f.slope == 1.0 and f.intercept == 0.0


def _axis_values(joint: Joint, q: cs.SX, u: cs.SX | None, s: cs.SX) -> tuple[list, cs.SX, cs.SX]:
    """Values of a CustomJoint's six axes (translations other than pure coordinate axes
    scaled by ``s``), ``d value/dq`` ``(6, k)`` and ``f'' u_c^2`` ``(6, 1)``."""
    k = len(joint.coordinates)
    index = {name: i for i, name in enumerate(joint.coordinates)}
    fq = cs.SX.zeros(6, k)
    second = cs.SX.zeros(6, 1)
    values = []
    for i, axis in enumerate(joint.transform_axes):
        factor = s if i >= 3 and not _is_coordinate_axis(axis) else 1.0
        if axis.coordinates:
            c = index[axis.coordinates[0]]
            val, der, der2 = value_and_derivatives(axis.function, q[c])
            fq[i, c] = der * factor
            if u is not None:
                second[i] = der2 * factor * u[c] ** 2
        else:
            val = axis.function(0.0)
        values.append(val * factor)
    return values, fq, second


def _custom_pose(joint: Joint, values: list) -> tuple[cs.SX, cs.SX]:
    rotation = cs.SX.eye(3)
    translation = cs.SX.zeros(3, 1)
    for index, axis in enumerate(joint.transform_axes):
        direction = np.asarray(axis.axis, dtype=float)
        if index < 3:
            rotation = cs.mtimes(rotation, axis_angle(direction, values[index]))
        else:
            translation = translation + values[index] * cs.DM(direction / np.linalg.norm(direction))
    return rotation, translation


def joint_pose(joint: Joint, q: cs.SX, s: cs.SX) -> tuple[cs.SX, cs.SX]:
    """``(R_FM, p_FM)`` of ``joint`` at its coordinates ``q`` (SX, length k)."""
    t = joint.type
    zero = cs.SX.zeros(3, 1)
    if t == "CustomJoint":
        return _custom_pose(joint, _axis_values(joint, q, None, s)[0])
    if t == "WeldJoint":
        return cs.SX.eye(3), zero
    if t == "PinJoint":
        return axis_angle(_Z, q[0]), zero
    if t == "SliderJoint":
        return cs.SX.eye(3), cs.vertcat(q[0], 0, 0)
    if t == "UniversalJoint":
        return cs.mtimes(axis_angle(_X, q[0]), axis_angle(_Y, q[1])), zero
    if t in ("GimbalJoint", "BallJoint"):
        return body_xyz(q[0:3]), zero
    if t == "PlanarJoint":
        return axis_angle(_Z, q[0]), cs.vertcat(q[1], q[2], 0)
    if t == "FreeJoint":
        return body_xyz(q[0:3]), q[3:6]
    raise ModelError(f"joint type '{t}' is not supported", element=f"{t} '{joint.name}'")


def _custom_simbody_motion(joint: Joint, values: list, fq: cs.SX, second: cs.SX, u: cs.SX) -> tuple[cs.SX, ...]:
    """``(H_w, H_v, c_w, c_v)`` of a CustomJoint as Simbody's FunctionBased mobilizer
    computes them: the angular velocity is exact (``w = W theta_dot`` with
    ``W = [a1, R1 a2, R1 R2 a3]``), but the rate of ``W`` uses the angular velocities of
    the first mobility alone and of all mobilities except the third, which is exact only
    when mobility i drives rotation axis i."""
    k = fq.shape[1]
    units = [np.asarray(a.axis, dtype=float) / np.linalg.norm(a.axis) for a in joint.transform_axes]
    r1 = axis_angle(units[0], values[0])
    r2 = cs.mtimes(r1, axis_angle(units[1], values[1]))
    w_cols = [cs.DM(units[0]), cs.mtimes(r1, cs.DM(units[1])), cs.mtimes(r2, cs.DM(units[2]))]
    w_mat = cs.horzcat(*w_cols)
    a_trans = cs.horzcat(*[cs.DM(units[i]) for i in (3, 4, 5)])
    h_w = cs.mtimes(w_mat, fq[0:3, :])
    h_v = cs.mtimes(a_trans, fq[3:6, :])
    u1 = cs.vertcat(u[0], cs.SX.zeros(k - 1, 1)) if k > 1 else u
    u2 = cs.vertcat(u[0:2], 0, u[3:]) if k > 2 else u
    v1 = cs.mtimes(h_w, u1)
    v2 = cs.mtimes(h_w, u2)
    w_rate = cs.horzcat(cs.SX.zeros(3, 1), cs.cross(v1, w_cols[1]), cs.cross(v2, w_cols[2]))
    c_w = cs.mtimes(w_rate, cs.mtimes(fq[0:3, :], u)) + cs.mtimes(w_mat, second[0:3])
    c_v = cs.mtimes(a_trans, second[3:6])
    return h_w, h_v, c_w, c_v


_FIXED_AXIS_JOINTS = ("PinJoint", "SliderJoint", "UniversalJoint", "PlanarJoint", "GimbalJoint")


def _fixed_axis_motion(kind: str, q: cs.SX, u: cs.SX) -> tuple[cs.SX, ...]:
    """``(H_w, H_v, c_w, c_v)`` of the joints built from rotations about coordinate axes
    (closed form: ``w = sum_i (R_0..R_(i-1) e_i) u_i``, so constant columns stay constant)."""
    k = q.shape[0]
    h_w = cs.SX.zeros(3, k)
    h_v = cs.SX.zeros(3, k)
    c_w = cs.SX.zeros(3, 1)
    c_v = cs.SX.zeros(3, 1)
    if kind == "PinJoint":
        h_w[2, 0] = 1
    elif kind == "SliderJoint":
        h_v[0, 0] = 1
    elif kind == "PlanarJoint":
        h_w[2, 0] = 1
        h_v[0, 1] = 1
        h_v[1, 2] = 1
    else:  # Universal (X then Y), Gimbal (X, Y, Z body-fixed)
        axes = [_X, _Y, _Z][:k]
        rotation = cs.SX.eye(3)
        columns = []
        for i, axis in enumerate(axes):
            columns.append(cs.mtimes(rotation, cs.DM(axis)))
            rotation = cs.mtimes(rotation, axis_angle(axis, q[i]))
        h_w = cs.horzcat(*columns)
        partial = cs.SX.zeros(3, 1)  # angular velocity of the intermediate frame
        for i, column in enumerate(columns):
            c_w = c_w + cs.cross(partial, column) * u[i]
            partial = partial + column * u[i]
    return h_w, h_v, c_w, c_v


def joint_motion_function(joint: Joint, custom_joint_bias: str = "opensim") -> cs.Function:
    """The SX Function described in the module docstring, for ``joint``.

    ``custom_joint_bias``: ``"opensim"`` computes a CustomJoint's velocity-product terms as
    Simbody does (see :func:`_custom_simbody_motion`; matches OpenSim's inverse dynamics),
    ``"exact"`` differentiates the joint's kinematics exactly. They differ only for
    CustomJoints in which one coordinate drives several rotation axes (the RCNL knee).
    """
    if custom_joint_bias not in ("opensim", "exact"):
        raise ValueError(f"custom_joint_bias must be 'opensim' or 'exact', not '{custom_joint_bias}'")
    k = len(joint.coordinates)
    q = cs.SX.sym("q", k)
    u = cs.SX.sym("u", k)
    s = cs.SX.sym("s")
    if joint.type == "CustomJoint":
        values, fq, second = _axis_values(joint, q, u, s)
        rotation, translation = _custom_pose(joint, values)
    else:
        rotation, translation = joint_pose(joint, q, s)
    if joint.type in ANGULAR_VELOCITY_JOINTS:
        h_w = cs.SX.zeros(3, k)
        h_w[:, 0:3] = cs.SX.eye(3)
        c_w = cs.SX.zeros(3, 1)
        h_v = cs.SX.zeros(3, k)
        if k == 6:
            h_v[:, 3:6] = cs.SX.eye(3)
        c_v = cs.SX.zeros(3, 1)
    elif k and joint.type == "CustomJoint" and custom_joint_bias == "opensim":
        h_w, h_v, c_w, c_v = _custom_simbody_motion(joint, values, fq, second, u)
    elif joint.type in _FIXED_AXIS_JOINTS:
        h_w, h_v, c_w, c_v = _fixed_axis_motion(joint.type, q, u)
    elif k:
        rotation_rate = cs.jtimes(rotation, q, u)
        w = vee(cs.mtimes(rotation_rate, rotation.T))
        v = cs.jtimes(translation, q, u)
        h_w = cs.jacobian(w, u)
        h_v = cs.jacobian(v, u)
        c_w = cs.jtimes(w, q, u)
        c_v = cs.jtimes(v, q, u)
    else:
        h_w = cs.SX.zeros(3, 0)
        h_v = cs.SX.zeros(3, 0)
        c_w = cs.SX.zeros(3, 1)
        c_v = cs.SX.zeros(3, 1)
    return cs.Function(
        function_name("motion", joint.name), [q, u, s], [rotation, translation, h_w, h_v, c_w, c_v],
        ["q", "u", "s"], ["R", "p", "H_w", "H_v", "c_w", "c_v"], {"cse": True},
    )

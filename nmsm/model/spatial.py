"""Rotation algebra for CasADi expressions (SX or MX). Angles in rad; a rotation matrix
``R_AB`` (3x3) maps vectors expressed in frame B to frame A."""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np


def vee(m: Any) -> Any:
    """The vector ``a`` of a (nearly) skew-symmetric matrix ``m``, with ``m @ b ≈ a x b``."""
    return cs.vertcat(m[2, 1], m[0, 2], m[1, 0])


def axis_angle(axis: np.ndarray, angle: Any) -> Any:
    """Rotation by ``angle`` about the fixed unit vector ``axis`` (numpy, normalized here).

    Axis-aligned unit axes give the exact elementary matrices.
    """
    k = np.asarray(axis, dtype=float).reshape(3)
    k = k / np.linalg.norm(k)
    c = cs.cos(angle)
    s = cs.sin(angle)
    rows = []
    for i in range(3):
        row = []
        for j in range(3):
            entry = (1 - c) * (k[i] * k[j]) if k[i] * k[j] != 0.0 else 0
            if i == j:
                entry = entry + c
            else:
                # skew part: K[i, j] = -eps_ijk k_k
                m = 3 - i - j
                sign = 1.0 if (i, j) in ((2, 1), (0, 2), (1, 0)) else -1.0
                if k[m] != 0.0:
                    entry = entry + sign * k[m] * s
            row.append(entry)
        rows.append(cs.horzcat(*row))
    return cs.vertcat(*rows)


_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])


def body_xyz(angles: Any) -> Any:
    """Body-fixed X-Y-Z rotation ``Rx(a0) Ry(a1) Rz(a2)`` of a 3-vector of angles."""
    return cs.mtimes([axis_angle(_X, angles[0]), axis_angle(_Y, angles[1]), axis_angle(_Z, angles[2])])


def body_xyz_angles(r: Any) -> Any:
    """Body-fixed X-Y-Z angles of a rotation matrix (second angle in [-pi/2, pi/2])."""
    return cs.vertcat(cs.atan2(-r[1, 2], r[2, 2]), cs.asin(r[0, 2]), cs.atan2(-r[0, 1], r[0, 0]))


def constant(value: np.ndarray) -> cs.DM:
    return cs.DM(np.asarray(value, dtype=float))

"""Rotation matrices with numpy (numeric model data). CasADi versions live in
:mod:`nmsm.model.spatial`. Angles in rad; matrices (3, 3) map frame-B vectors to frame A.
"""

from __future__ import annotations

import numpy as np


def axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by ``angle`` about the unit vector ``axis`` (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * kx + (1.0 - np.cos(angle)) * (kx @ kx)


def body_xyz(angles: np.ndarray) -> np.ndarray:
    """Body-fixed X-Y-Z rotation: ``Rx(a0) @ Ry(a1) @ Rz(a2)``."""
    a = np.asarray(angles, dtype=float).reshape(3)
    return (axis_angle(np.array([1.0, 0, 0]), a[0]) @ axis_angle(np.array([0, 1.0, 0]), a[1])
            @ axis_angle(np.array([0, 0, 1.0]), a[2]))


def body_xyz_angles(rotation: np.ndarray) -> np.ndarray:
    """Body-fixed X-Y-Z angles (rad) of a rotation matrix; inverse of :func:`body_xyz`
    (second angle in [-pi/2, pi/2])."""
    r = np.asarray(rotation, dtype=float)
    a1 = np.arcsin(np.clip(r[0, 2], -1.0, 1.0))
    a0 = np.arctan2(-r[1, 2], r[2, 2])
    a2 = np.arctan2(-r[0, 1], r[0, 0])
    return np.array([a0, a1, a2])

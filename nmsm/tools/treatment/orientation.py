"""Body-fixed (intrinsic) Tait-Bryan angles from rotation matrices, for any axis sequence.

For a sequence ``ijk`` (e.g. ``xyz``), ``R = R_i(a) R_j(b) R_k(c)`` with ``R`` the rotation
of the body in ground (columns = body axes). :func:`euler_angles` returns ``(a, b, c)`` (rad),
the angles about the sequence's first, second and third axes. Works on numpy arrays and
CasADi expressions.
"""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np

SEQUENCES = ("xyz", "xzy", "yxz", "yzx", "zxy", "zyx")
_AXIS = {"x": 0, "y": 1, "z": 2}


def check_sequence(sequence: str) -> str:
    seq = (sequence or "xyz").strip().lower()
    if seq not in SEQUENCES:
        raise ValueError(f"rotation sequence '{sequence}' is not supported (expected one of {', '.join(SEQUENCES)})")
    return seq


def euler_angles(R: Any, sequence: str = "xyz") -> list[Any]:
    """``[a, b, c]`` of ``R = R_i(a) R_j(b) R_k(c)`` for ``sequence = 'ijk'``.

    ``R`` is a (3, 3) numpy array or CasADi matrix of one rotation.
    """
    seq = check_sequence(sequence)
    i, j, k = (_AXIS[c] for c in seq)
    eps = 1.0 if seq in ("xyz", "yzx", "zxy") else -1.0
    if isinstance(R, np.ndarray):
        atan2, sqrt = np.arctan2, np.sqrt
    else:
        atan2, sqrt = cs.atan2, cs.sqrt
    a = atan2(-eps * R[j, k], R[k, k])
    b = atan2(eps * R[i, k], sqrt(R[j, k] ** 2 + R[k, k] ** 2))
    c = atan2(-eps * R[i, j], R[i, i])
    return [a, b, c]


def rotation(axis: str, angle: float) -> np.ndarray:
    """Elementary rotation matrix about ``axis`` (numpy)."""
    c, s = np.cos(angle), np.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])

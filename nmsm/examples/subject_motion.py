"""The synthetic subject's *reference* gait: what its controller tries to walk.

The forward simulation (:mod:`nmsm.examples.subject_simulation`) tracks this reference;
the recorded movement is the simulation's, not this. Periodic with period
:data:`CYCLE` (s); the right heel strikes at :data:`HEEL_STRIKE` + k·CYCLE.

* Prescribed coordinates (analytic, with exact derivatives): the pelvis walks forward at
  :data:`SPEED` (m/s) with small vertical and tilt oscillations; the gait is in the
  sagittal plane (pelvis list, rotation, lateral translation, hip adduction and rotation
  stay 0, so the planted foot never slides sideways).
* The foot: heel rocker (pitch from +0.25 rad to flat about the heel), flat foot, toe
  rocker (pitch to -0.5 rad about the toes joint, the toes flat), then swing to the next
  heel strike one stride (SPEED·CYCLE) ahead, with minimum-jerk blends and a 6 cm
  clearance bump. The sole sits :data:`SOLE_HEIGHT` above the floor during stance (the
  springs' resting length is larger, so they are compressed).
* Hip flexion, knee and ankle angles follow from the foot by inverse kinematics of the
  model (Gauss-Newton per frame on the hindfoot's position and pitch), the toes angle from
  the toe rocker.

Units: s, m, rad.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np

CYCLE = 1.1
SPEED = 0.9
HEEL_STRIKE = 0.2
SOLE_HEIGHT = 0.006
#: phase fractions: end of heel rocker, start of toe rocker, toe-off
HEEL_ROCKER_END, TOE_ROCKER_START, TOE_OFF = 0.07, 0.36, 0.62
HEEL_STRIKE_PITCH, TOE_OFF_PITCH = 0.25, -0.5
CLEARANCE = 0.06
#: prescribed coordinates: name -> (mean, amplitude, harmonic, phase) of a sine (rad or m);
#: pelvis_tx adds SPEED * t, pelvis_ty the standing height
PRESCRIBED: dict[str, tuple[float, float, int, float]] = {
    "pelvis_tilt": (-0.05, 0.03, 2, 0.3),
    "pelvis_list": (0.0, 0.0, 1, 0.0),
    "pelvis_rotation": (0.0, 0.0, 1, 0.0),
    "pelvis_tx": (0.0, 0.0, 1, 0.0),
    "pelvis_ty": (-0.02, 0.015, 2, -np.pi / 2),
    "pelvis_tz": (0.0, 0.0, 1, 0.0),
    "hip_adduction_r": (0.0, 0.0, 1, 0.0),
    "hip_rotation_r": (0.0, 0.0, 1, 0.0),
}
#: coordinates solved by inverse kinematics (then simulated), in order
LEG = ("hip_flexion_r", "knee_angle_r", "ankle_angle_r", "mtp_angle_r")


def prescribed_values(name: str, t: np.ndarray, standing_height: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Value, rate and acceleration (each ``t.shape``) of a prescribed coordinate."""
    mean, amplitude, harmonic, phase = PRESCRIBED[name]
    w = 2 * np.pi * harmonic / CYCLE
    arg = w * (t - HEEL_STRIKE) + phase
    q = mean + amplitude * np.sin(arg)
    qd = amplitude * w * np.cos(arg)
    qdd = -amplitude * w**2 * np.sin(arg)
    if name == "pelvis_tx":
        q, qd = q + SPEED * t, qd + SPEED
    if name == "pelvis_ty":
        q = q + standing_height
    return q, qd, qdd


def _smooth(s: np.ndarray) -> np.ndarray:
    """Minimum-jerk blend 0 -> 1 on s in [0, 1]."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s**2)


@attrs.frozen
class FootPose:
    """Hindfoot origin ``(x, y)`` (m), pitch (rad, toes up positive) and toes angle (rad)."""

    x: np.ndarray
    y: np.ndarray
    pitch: np.ndarray
    toes: np.ndarray


def _rotate(point: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """``point`` (2,) of the hindfoot frame rotated by ``pitch``: (n, 2)."""
    c, s = np.cos(pitch), np.sin(pitch)
    return np.stack([c * point[0] - s * point[1], s * point[0] + c * point[1]], axis=-1)


def foot_pose(t: np.ndarray, heel: Sequence[float], toes_joint: Sequence[float], sole_depth: float) -> FootPose:
    """The reference hindfoot pose at times ``t`` (see module docstring); ``heel`` and
    ``toes_joint`` are (x, y) points of the hindfoot frame, ``sole_depth`` the sole's
    depth below the hindfoot origin (m)."""
    t = np.asarray(t, dtype=float)
    cycle = np.floor((t - HEEL_STRIKE) / CYCLE)
    phase = (t - HEEL_STRIKE) / CYCLE - cycle
    heel_bottom = np.array([heel[0], -sole_depth])
    toes_bottom = np.array([toes_joint[0], -sole_depth])
    x_heel_strike = SPEED * (HEEL_STRIKE + cycle * CYCLE) + 0.12  # heel contact point on the floor
    floor = SOLE_HEIGHT
    pitch = np.zeros_like(t)
    toes = np.zeros_like(t)
    origin = np.zeros((t.size, 2))
    # flat-foot origin (heel bottom at x_heel_strike, sole at the floor height)
    flat = np.stack([x_heel_strike - heel_bottom[0], floor - heel_bottom[1] + 0 * t], axis=-1)
    a = phase < HEEL_ROCKER_END
    pitch[a] = HEEL_STRIKE_PITCH * (1 - _smooth(phase[a] / HEEL_ROCKER_END))
    pivot = np.stack([x_heel_strike, floor + 0 * t], axis=-1)
    origin[a] = pivot[a] - _rotate(heel_bottom, pitch[a])
    b = (phase >= HEEL_ROCKER_END) & (phase < TOE_ROCKER_START)
    origin[b] = flat[b]
    c = (phase >= TOE_ROCKER_START) & (phase < TOE_OFF)
    s = (phase[c] - TOE_ROCKER_START) / (TOE_OFF - TOE_ROCKER_START)
    pitch[c] = TOE_OFF_PITCH * _smooth(s)
    toes_pivot = flat[c] + toes_bottom
    origin[c] = toes_pivot - _rotate(toes_bottom, pitch[c])
    toes[c] = -pitch[c]
    d = phase >= TOE_OFF
    s = (phase[d] - TOE_OFF) / (1 - TOE_OFF)
    blend = _smooth(s)
    off_pivot = flat[d] + toes_bottom
    start = off_pivot - _rotate(toes_bottom, np.full(s.shape, TOE_OFF_PITCH))
    end = (pivot[d] + [SPEED * CYCLE, 0.0]) - _rotate(heel_bottom, np.full(s.shape, HEEL_STRIKE_PITCH))
    origin[d] = start + blend[:, None] * (end - start)
    origin[d, 1] += CLEARANCE * np.sin(np.pi * (1 - (1 - s) ** 2)) ** 2  # early lift, smooth start
    pitch[d] = TOE_OFF_PITCH + (HEEL_STRIKE_PITCH - TOE_OFF_PITCH) * blend
    toes[d] = -TOE_OFF_PITCH * (1 - _smooth(2 * s))
    return FootPose(origin[:, 0], origin[:, 1], pitch, toes)


def leg_inverse_kinematics(model, t: np.ndarray, pose: FootPose, standing_height: float,
                           hindfoot: str = "calcn_r") -> np.ndarray:
    """All coordinates ``(len(t), n)`` (model order): prescribed ones from
    :func:`prescribed_values`, hip flexion, knee and ankle solving the hindfoot origin's
    x, y and pitch (Gauss-Newton, exact CasADi Jacobian), the toes from the pose."""
    import casadi as cs

    from nmsm.model.casadi_model import CasadiModel

    cm = CasadiModel(model)
    names = model.coordinate_names
    index = [names.index(c) for c in LEG[:3]]
    q = cs.SX.sym("q", len(names))
    rotation, origin = cm.body_pose_function(hindfoot)(q)
    pitch = cs.atan2(rotation[1, 0], rotation[0, 0])
    residual = cs.vertcat(origin[0], origin[1], pitch)
    x = cs.vertcat(*[q[i] for i in index])
    frame = cs.Function("foot", [q], [residual, cs.jacobian(residual, x)])
    out = np.zeros((t.size, len(names)))
    for name in PRESCRIBED:
        out[:, names.index(name)] = prescribed_values(name, t, standing_height)[0]
    out[:, names.index("mtp_angle_r")] = pose.toes
    guess = np.array([0.3, 0.4, 0.0])
    for k in range(t.size):
        target = np.array([pose.x[k], pose.y[k], pose.pitch[k]])
        for _ in range(30):
            out[k, index] = guess
            value, jac = (np.array(v) for v in frame(out[k]))
            step = np.linalg.lstsq(jac, target - value.ravel(), rcond=None)[0]
            step *= min(1.0, 0.3 / max(np.max(np.abs(step)), 1e-300))  # at most 0.3 rad per step
            guess = guess + step
            guess[1] = max(guess[1], 0.02)  # the flexed-knee solution, never hyperextension
            if np.max(np.abs(step)) < 1e-12:
                break
        out[k, index] = guess
    return out

"""The synthetic subject's known parameters: what each personalization tool should recover.

* Joints (JMP): the true model's joint frames are the built ones; the generic model the
  pipeline starts from has the knee's parent and child frames and the ankle's parent frame
  rotated about x and y by :data:`JOINT_PERTURBATION` (rad).
* Muscles (MTP): activation time constant (s), activation nonlinearity, electromechanical
  delay (s), optimal fiber length and tendon slack length of every muscle; the generic model
  has lengths divided by :data:`LENGTH_SCALES` (so MTP's scale factors should come out as
  those numbers). The EMG scale factor maps the *processed* EMG (normalized by its maximum)
  to the excitation: :func:`nmsm.examples.subject.effective_emg_scales`.
* Synergies (NCP): the excitation synergy vectors ``W`` (S x M, largest weight 1).
* Foot contact (GCP): spring constants (N/m) over the GCP spring grid, damping (s/m),
  friction coefficients and resting spring length (m).

Tendon slack lengths are set so that the mean normalized fiber length over the reference
gait is :data:`MEAN_FIBER_LENGTH` (:func:`tendon_slack_lengths`).
"""

from __future__ import annotations

from collections.abc import Mapping

import attrs
import numpy as np

from nmsm.examples.subject_model import MUSCLES

#: rad; (joint, frame) -> x, y rotation of the generic model (multiples of the perturbation)
JOINT_PERTURBATION = np.radians(5.0)
JOINT_PATTERN: dict[tuple[str, str], tuple[float, float]] = {
    ("knee_r", "parent"): (1.0, -0.8),
    ("knee_r", "child"): (-0.6, 0.9),
    ("ankle_r", "parent"): (0.7, -1.0),
}
#: true muscle properties per muscle (MUSCLES order): activation time constant (s),
#: nonlinearity, electromechanical delay (s)
ACTIVATION_TIME_CONSTANTS = (0.0080, 0.0100, 0.0090, 0.0095, 0.0085, 0.0100, 0.0090, 0.0080)
NONLINEARITY = (0.10, 0.20, 0.15, 0.08, 0.25, 0.12, 0.18, 0.22)
DELAYS = (0.05, 0.07, 0.04, 0.06, 0.08, 0.05, 0.07, 0.06)
#: true / generic optimal fiber length and tendon slack length
LENGTH_SCALES = ((1.10, 0.95), (0.92, 1.04), (1.08, 0.97), (0.94, 1.05), (1.06, 0.96), (0.90, 1.03),
                 (1.12, 0.98), (0.95, 1.06))
MEAN_FIBER_LENGTH = 0.95
#: number of excitation synergies
N_SYNERGIES = 5
#: contact: damping (s/m), dynamic and viscous friction, resting length (m), latching velocity (m/s)
CONTACT = {"damping_factor": 0.25, "dynamic_friction_coefficient": 0.7, "viscous_friction_coefficient": 0.3,
           "resting_spring_length": 0.012, "latching_velocity": 0.05}
#: mean spring constant (N/m) and its heel-to-toe rise (fraction)
SPRING_CONSTANT, SPRING_GRADIENT = 1200.0, 0.5


@attrs.frozen
class MuscleTruth:
    """One muscle's true properties (SI)."""

    name: str
    channel: str
    max_isometric_force: float
    pennation: float
    optimal_fiber_length: float
    tendon_slack_length: float
    activation_time_constant: float
    nonlinearity: float
    delay: float
    optimal_fiber_length_scale: float  #: true / generic
    tendon_slack_length_scale: float  #: true / generic


def muscle_truths(tendon_slack: Mapping[str, float]) -> tuple[MuscleTruth, ...]:
    """The muscles' truth (MUSCLES order) given their true tendon slack lengths (m)."""
    out = []
    for k, (name, spec) in enumerate(MUSCLES.items()):
        out.append(MuscleTruth(
            name=name, channel=spec.channel, max_isometric_force=spec.max_isometric_force,
            pennation=spec.pennation, optimal_fiber_length=spec.optimal_fiber_length,
            tendon_slack_length=float(tendon_slack[name]),
            activation_time_constant=ACTIVATION_TIME_CONSTANTS[k], nonlinearity=NONLINEARITY[k], delay=DELAYS[k],
            optimal_fiber_length_scale=LENGTH_SCALES[k][0], tendon_slack_length_scale=LENGTH_SCALES[k][1],
        ))
    return tuple(out)


def tendon_slack_lengths(lengths: np.ndarray) -> dict[str, float]:
    """True tendon slack lengths (m) from muscle-tendon lengths ``(frames, M)`` over the
    reference gait: mean normalized fiber length :data:`MEAN_FIBER_LENGTH`."""
    out = {}
    for k, (name, spec) in enumerate(MUSCLES.items()):
        fiber = MEAN_FIBER_LENGTH * spec.optimal_fiber_length * np.cos(spec.pennation)
        out[name] = float(np.mean(lengths[:, k]) - fiber)
    return out


def generic_lengths(truths: tuple[MuscleTruth, ...]) -> tuple[dict[str, float], dict[str, float]]:
    """(optimal fiber lengths, tendon slack lengths) of the generic model (m)."""
    return ({m.name: m.optimal_fiber_length / m.optimal_fiber_length_scale for m in truths},
            {m.name: m.tendon_slack_length / m.tendon_slack_length_scale for m in truths})


def generic_frame_orientations() -> dict[tuple[str, str], tuple[float, float, float]]:
    """The generic model's rotated joint frames (body-fixed X-Y-Z, rad)."""
    return {key: (JOINT_PERTURBATION * a, JOINT_PERTURBATION * b, 0.0) for key, (a, b) in JOINT_PATTERN.items()}


def spring_constants(locations_x: np.ndarray) -> np.ndarray:
    """True spring constants (N/m): rising linearly from heel to toe (``locations_x``:
    the springs' heel-to-toe position, any units)."""
    x = np.asarray(locations_x, dtype=float)
    span = max(float(x.max() - x.min()), 1e-12)
    s = (x - x.min()) / span
    return SPRING_CONSTANT * (1.0 + SPRING_GRADIENT * (s - 0.5))

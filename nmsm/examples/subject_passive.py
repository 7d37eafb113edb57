"""The synthetic subject's passive trials: the leg moved slowly by an examiner, muscles relaxed.

Muscle-Tendon Length Initialization (MTLI) fits optimal fiber and tendon slack lengths to
passive joint moments (docs/mtp.md); the original's tutorial ships passive trials for this.
Each trial here sweeps one coordinate at constant speed with the other two held, the hip,
knee and ankle each at three settings of a neighbouring joint so that the one- and two-joint
muscles stretch in different combinations:

* :data:`PASSIVE_TRIALS` - name -> (swept coordinate, start and end (deg), held coordinates (deg));
* :func:`passive_poses` - the trial's coordinates (T, n) in model order (rad, m);
* :func:`passive_moments` - the relaxed muscles' joint moments (T, C) N m on the muscle
  coordinates: ``sum_m r_cm F_P,m`` with the true lengths and the passive force of the
  simulation (:func:`nmsm.model.hill.passive_tendon_force`), what a dynamometer measures once
  the limb's weight is subtracted.

Moment magnitudes stay below about 90 N m. Time on axis 0; SI units.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from nmsm.examples import subject_model as sm
from nmsm.examples.subject_truth import MuscleTruth
from nmsm.model import hill

#: duration (s) of each sweep
PASSIVE_DURATION = 3.0
#: name -> (swept coordinate, (start, end) deg, held coordinates deg)
PASSIVE_TRIALS: dict[str, tuple[str, tuple[float, float], dict[str, float]]] = {
    "passive_hip_knee5": ("hip_flexion_r", (-20.0, 30.0), {"knee_angle_r": 5.0, "ankle_angle_r": 0.0}),
    "passive_hip_knee70": ("hip_flexion_r", (-10.0, 90.0), {"knee_angle_r": 70.0, "ankle_angle_r": 0.0}),
    "passive_hip_knee85": ("hip_flexion_r", (0.0, 90.0), {"knee_angle_r": 85.0, "ankle_angle_r": 0.0}),
    "passive_knee_hip0": ("knee_angle_r", (0.0, 75.0), {"hip_flexion_r": 0.0, "ankle_angle_r": 0.0}),
    "passive_knee_hip60": ("knee_angle_r", (35.0, 100.0), {"hip_flexion_r": 60.0, "ankle_angle_r": 0.0}),
    "passive_ankle_knee5": ("ankle_angle_r", (-30.0, 20.0), {"hip_flexion_r": 0.0, "knee_angle_r": 5.0}),
    "passive_ankle_knee30": ("ankle_angle_r", (-30.0, 20.0), {"hip_flexion_r": 0.0, "knee_angle_r": 30.0}),
    "passive_ankle_knee60": ("ankle_angle_r", (-30.0, 20.0), {"hip_flexion_r": 0.0, "knee_angle_r": 60.0}),
    "passive_ankle_knee85": ("ankle_angle_r", (-30.0, 25.0), {"hip_flexion_r": 0.0, "knee_angle_r": 85.0}),
}


def passive_poses(names: Sequence[str], trial: str, time: np.ndarray, standing_height: float) -> np.ndarray:
    """Coordinates (T, n) in the order of ``names`` (rad; pelvis translations m): the swept
    coordinate linear from start to end over ``time``, held ones fixed, the pelvis level at
    ``standing_height``, every other coordinate zero."""
    swept, (start, end), held = PASSIVE_TRIALS[trial]
    q = np.zeros((time.size, len(names)))
    fraction = (time - time[0]) / (time[-1] - time[0])
    for j, name in enumerate(names):
        if name == swept:
            q[:, j] = np.radians(start + (end - start) * fraction)
        elif name in held:
            q[:, j] = np.radians(held[name])
        elif name == "pelvis_ty":
            q[:, j] = standing_height
    return q


def passive_moments(model: Any, muscles: Sequence[MuscleTruth], q: np.ndarray) -> np.ndarray:
    """Passive joint moments (T, C) N m on :data:`~nmsm.examples.subject_model.MUSCLE_COORDINATES`
    of relaxed ``muscles`` (true lengths) at coordinates ``q`` (T, n_q, model order) of the
    parsed ``model`` (:func:`nmsm.model.osim.load_model`)."""
    from nmsm.model.muscle_geometry import MuscleGeometry

    names = [m.name for m in muscles]
    geometry = MuscleGeometry(model, names, list(sm.MUSCLE_COORDINATES)).function().map(q.shape[0])
    lengths, _, arms = geometry(q.T, np.zeros(q.T.shape))
    lengths = np.array(lengths).T  # (T, M)
    arms = np.array(arms).reshape(len(names), len(sm.MUSCLE_COORDINATES), q.shape[0], order="F")  # (M, C, T)
    lo, lts, alpha, f0 = (np.array([getattr(m, f) for m in muscles]) for f in
                          ("optimal_fiber_length", "tendon_slack_length", "pennation", "max_isometric_force"))
    normalized = hill.normalized_fiber_length(lengths, lo, lts, alpha)
    force = np.asarray(hill.passive_tendon_force(normalized, f0, alpha), dtype=float)  # (T, M)
    return np.einsum("mct,tm->tc", arms, force)


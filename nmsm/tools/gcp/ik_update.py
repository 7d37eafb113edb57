"""The full-body motion updated to the optimized foot kinematics (``IKData/gcp_modeled_*``).

As the original: every model marker is placed where the input motion puts
it, the foot markers of each personalized foot are replaced by their modeled positions,
and inverse kinematics is re-run with weight 1000 on those foot markers and 1 on the
others (nmsm's IK, :func:`nmsm.tools.jmp.ik.inverse_kinematics`); the coordinates are then
low-pass filtered (4th-order Butterworth, 6 Hz, zero phase).

Arrays: ``time`` (T,) s, coordinates (T, n) rad/m in model order, marker targets (T, 3) m.
"""

from __future__ import annotations

from collections.abc import Mapping

import attrs
import numpy as np

from nmsm.model.casadi_model import CasadiModel
from nmsm.tools.gcp.filtering import lowpass
from nmsm.tools.jmp.ik import IkResult, inverse_kinematics
from nmsm.tools.jmp.marker_data import MarkerTrial
from nmsm.tools.jmp.marker_model import MarkerKinematics

#: IK weight of the replaced foot markers
FOOT_MARKER_WEIGHT = 1000.0
#: low-pass of the updated coordinates: (order, cutoff Hz)
COORDINATE_FILTER = (4, 6.0)


def updated_motion(casadi_model: CasadiModel, time: np.ndarray, q_full: np.ndarray,
                   foot_targets: Mapping[str, np.ndarray]) -> IkResult:
    """IK of the input motion's markers with ``foot_targets`` (marker -> (T, 3)) replacing
    the foot markers; coordinates low-pass filtered (module docstring)."""
    model = casadi_model.model
    names = tuple(model.marker_names)
    marker_function = casadi_model.marker_function()
    positions = np.stack([np.array(marker_function(q)).T for q in q_full])  # (T, M, 3)
    weights = np.ones(len(names))
    for name, target in foot_targets.items():
        k = names.index(name)
        positions[:, k, :] = target
        weights[k] = FOOT_MARKER_WEIGHT
    trial = MarkerTrial(time=np.asarray(time, dtype=float), names=names, positions=positions, weights=weights)
    kinematics = MarkerKinematics(model, names)
    index = {n: i for i, n in enumerate(model.coordinate_names)}
    initial = np.array([q_full[0, index[n]] for n in kinematics.free_names])
    result = inverse_kinematics(model, trial, initial=initial, check_marker_units=False)
    order, cutoff = COORDINATE_FILTER
    return attrs.evolve(result, q=lowpass(result.time, result.q, order, cutoff))

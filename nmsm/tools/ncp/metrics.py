"""Fit quality of a synergy solution: joint-moment and activation errors.

``moment_rms``: per tracked coordinate, RMS over every trial and frame of
``M_muscles - M_ID`` (N·m; N for translational coordinates).
``activation_rms``: per muscle with MTP activations, RMS of ``a_NCP - a_MTP`` (-), and
the pooled RMS over those muscles. Activations and moments are those of the synergy
activations alone (not the combined MTP/NCP activations written to files).
"""

from __future__ import annotations

import attrs
import numpy as np

from nmsm.tools.ncp.forces import moment_gains
from nmsm.tools.ncp.inputs import NcpInputs
from nmsm.tools.ncp.nmf import variance_accounted_for
from nmsm.tools.ncp.solution import SynergySolution


@attrs.frozen
class FitMetrics:
    """``moment_rms`` (J,) per coordinate; ``activation_rms`` (K,) per MTP muscle (empty without MTP data);
    ``activation_rms_pooled`` over all MTP muscles (NaN without); ``activation_vaf`` of the NCP
    activations with respect to MTP's (fraction, NaN without)."""

    coordinates: tuple[str, ...]
    moment_rms: np.ndarray
    mtp_muscles: tuple[str, ...]
    activation_rms: np.ndarray
    activation_rms_pooled: float
    activation_vaf: float

    @property
    def mean_moment_rms(self) -> float:
        """Mean over coordinates of the per-coordinate RMS."""
        return float(np.mean(self.moment_rms)) if self.moment_rms.size else float("nan")


def fit_metrics(inputs: NcpInputs, solution: SynergySolution) -> FitMetrics:
    """Moment and activation errors of ``solution`` on ``inputs``."""
    squared = np.zeros(len(inputs.coordinates))
    frames = 0
    act_errors, act_mtp, act_ncp = [], [], []
    idx = list(inputs.mtp_indices)
    for t, trial in enumerate(inputs.trials):
        a = solution.activations(t)
        moments = moment_gains(trial, inputs.muscles, inputs.v_max_factor, inputs.curves).moments(a)
        squared += np.sum((moments - trial.moments) ** 2, axis=0)
        frames += trial.n_points
        if idx and trial.mtp_activations is not None:
            act_errors.append(a[:, idx] - trial.mtp_activations)
            act_mtp.append(trial.mtp_activations)
            act_ncp.append(a[:, idx])
    moment_rms = np.sqrt(squared / max(frames, 1))
    if act_errors:
        errors = np.vstack(act_errors)
        per_muscle = np.sqrt(np.mean(errors**2, axis=0))
        pooled = float(np.sqrt(np.mean(errors**2)))
        vaf = variance_accounted_for(np.vstack(act_mtp), np.vstack(act_ncp))
    else:
        per_muscle, pooled, vaf = np.zeros(0), float("nan"), float("nan")
    return FitMetrics(
        coordinates=inputs.coordinates,
        moment_rms=moment_rms,
        mtp_muscles=inputs.mtp_muscles,
        activation_rms=per_muscle,
        activation_rms_pooled=pooled,
        activation_vaf=vaf,
    )

"""Helpers reading the original's 2023 MTP / MTLI unit-test arrays (``mtp/*_unit_2023``).

MATLAB arrays are ``[trial, muscle, frame]``; expected arrays were stored permuted
(``(frame, trial, muscle)``). Everything here returns per-trial ``(frame, k)`` arrays.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from nmsm.tools.mtp import emg_spline
from nmsm.tools.mtp.data import TrialData
from nmsm.tools.mtp.model import MuscleDesign
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters
from nmsm.tools.mtp.synx import SynergyExtrapolation

P = "inputData."
SX = P + "synergyExtrapolation."


def folder(shared: Path, case: str) -> Path:
    return shared / "mtp" / "cost_function_unit_2023" / f"{case}_synergy_extrapolation" / "npz"


def load(shared: Path, case: str, name: str) -> dict[str, np.ndarray]:
    return dict(np.load(folder(shared, case) / f"{name}.npz"))


def per_trial(array: np.ndarray) -> list[np.ndarray]:
    """Expected ``(frame, trial, k)`` -> list of ``(frame, k)``."""
    return [array[:, t, :] for t in range(array.shape[1])]


def cells(d: dict[str, np.ndarray], key: str) -> list[np.ndarray]:
    out, i = [], 0
    while f"{key}{{{i}}}" in d:
        out.append(np.atleast_1d(d[f"{key}{{{i}}}"]))
        i += 1
    return out


def index_groups(d: dict[str, np.ndarray], key: str) -> tuple[tuple[int, ...], ...]:
    """MATLAB 1-based index cells -> 0-based tuples."""
    return tuple(tuple(int(v) - 1 for v in g) for g in cells(d, key))


def muscles(d: dict[str, np.ndarray]) -> MuscleParameters:
    n = d[P + "optimalFiberLength"].size
    return MuscleParameters([f"m{i}" for i in range(n)], d[P + "maxIsometricForce"], d[P + "optimalFiberLength"],
                            d[P + "tendonSlackLength"], d[P + "pennationAngle"])


def design(d: dict[str, np.ndarray]) -> MuscleDesign:
    return MuscleDesign(d["electromechanicalDelays"], d["activationTimeConstants"], d["activationNonlinearityConstants"],
                        d["emgScaleFactors"], d["optimalFiberLengthScaleFactors"], d["tendonSlackLengthScaleFactors"])


def trials(d: dict[str, np.ndarray], emg: list[np.ndarray]) -> list[TrialData]:
    """Trials with EMG samples ``emg[t]`` (n_emg, n_muscles)."""
    pad = int(d[P + "numPaddingFrames"])
    out = []
    for t in range(d[P + "emgTime"].shape[0]):
        emg_time = d[P + "emgTime"][t]
        out.append(TrialData(
            f"trial{t}", emg_time[pad:-pad], d[P + "muscleTendonLength"][t].T, d[P + "muscleTendonVelocity"][t].T,
            np.transpose(d[P + "momentArms"][t], (2, 0, 1)), d[P + "experimentalMoments"][t].T, emg_time, emg[t], pad,
        ))
    return out


def spline_samples(d: dict[str, np.ndarray], splines: dict[str, np.ndarray] | None = None) -> list[np.ndarray]:
    """EMG samples at the breaks of the stored not-a-knot splines (every 4th sample; others 0)."""
    t_all = d[P + "emgTime"]
    n_muscles = d[P + "optimalFiberLength"].size
    out = []
    for t in range(t_all.shape[0]):
        samples = np.zeros((t_all.shape[1], n_muscles))
        for m in range(n_muscles):
            key = P + f"emgSplines{{{t},{m}}}"
            src, k = (d, key) if key + ".coefs" in d else (splines, f"emgSplines{{{t},{m}}}")
            assert src is not None
            samples[::4, m] = emg_spline.evaluate_pp(src[k + ".breaks"], src[k + ".coefs"][:, :, None], t_all[t, ::4])[:, 0]
        out.append(samples)
    return out


def groups(d: dict[str, np.ndarray], key: str) -> tuple[MuscleGroup, ...]:
    return tuple(MuscleGroup(str(i), g) for i, g in enumerate(index_groups(d, key)))


def synergy_extrapolation(d: dict[str, np.ndarray]) -> SynergyExtrapolation:
    """The stored SynX set-up (PCA commands as stored)."""
    return SynergyExtrapolation(
        method=str(d[SX + "matrixFactorizationMethod"]),
        n_synergies=int(d[SX + "numberOfSynergies"]),
        n_frames=d[P + "emgTime"].shape[1],
        n_trials=d[P + "emgTime"].shape[0],
        missing_muscles=index_groups(d, SX + "missingEmgChannelGroups"),
        channel_muscles=index_groups(d, SX + "currentEmgChannelGroups"),
        extrapolation_categories=index_groups(d, SX + "synergyCategorizationOfTrials"),
        residual_categories=index_groups(d, SX + "residualCategorizationOfTrials"),
        extrapolation_commands=tuple(cells(d, P + "extrapolationCommands")),
        residual_commands=tuple(cells(d, P + "residualCommands")),
    )

"""``nmsm muscle-analysis`` against OpenSim's MuscleAnalysis on every shared model with muscles."""

from __future__ import annotations

import hashlib
import warnings

import attrs
import numpy as np
import pytest

from nmsm.io.storage import read_storage
from nmsm.model import load_model
from nmsm.model.muscle_analysis_check import compare_with_opensim, gait_motion

GAIT = "preprocessing/uf_subject3_tutorial/PreCompleted/input_data/GaitTrial_IKResults.mot"
#: gait frames 0.10-0.30 s every 0.04 s: each gastrocnemius condyle wrap of the Rajagopal family
#: engages or lets go between two of them (0.16 and 0.25 s on the right, 0.10 s on the left)
TIMES = np.round(np.arange(0.10, 0.3001, 0.04), 2)
#: the issue's criteria (m): moment arms RMS over frames, lengths RMS
MOMENT_ARM_RMS, LENGTH_RMS = 1e-3, 5e-4


@pytest.mark.slow
def test_every_shared_model_matches_opensim_muscle_analysis(shared_data, bridge, tmp_path) -> None:
    gait = read_storage(shared_data / GAIT)
    keep = np.isin(np.round(gait.time, 2), TIMES)
    gait = attrs.evolve(gait, time=gait.time[keep], data=gait.data[keep])
    seen: set[str] = set()
    worst = (0.0, "")
    checked = 0
    for k, path in enumerate(sorted(shared_data.rglob("*.osim"))):
        digest = hashlib.sha256(path.read_bytes()).hexdigest()
        if digest in seen:
            continue
        seen.add(digest)
        model = load_model(path)
        if not model.muscles:
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # clamped and locked coordinates of the gait motion
            result = compare_with_opensim(path, gait_motion(model, gait), tmp_path / str(k), bridge=bridge,
                                          model=model)
        if not result.muscles:
            continue  # muscles outside the ForceSet: OpenSim's MuscleAnalysis reports none
        muscle, rms, coordinate = result.worst()
        label = f"{path.relative_to(shared_data)}: {muscle} ({coordinate})"
        assert rms <= MOMENT_ARM_RMS, label
        assert result.length_rms.max() <= LENGTH_RMS, label
        worst = max(worst, (rms, label))
        checked += 1
    assert checked >= 15
    print(f"{checked} models; worst moment-arm RMS {1e3 * worst[0]:.2e} mm: {worst[1]}")

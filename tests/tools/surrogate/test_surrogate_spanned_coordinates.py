"""Surrogate sampling through OpenSim: central differences only for the coordinates each
muscle spans (issue 24: sampling 86 muscles x 14 coordinates within a minute). The moment arms
of spanned coordinates do not depend on how the poses are split into worker calls (each call
probes its own first, middle and last poses); those of coordinates a muscle does not span are
exactly zero."""

from __future__ import annotations

import numpy as np

from nmsm.core.progress import progress_every
from nmsm.io.storage import read_storage
from nmsm.tools.surrogate import sampling

KICK = "treatment/surrogate_kick_tutorial"
COORDINATES = ("hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r",
               "subtalar_angle_r")


def test_spanned_coordinates_only_and_exact_zeros(shared_data, bridge, monkeypatch) -> None:
    model_file = shared_data / KICK / "RightLegAndPelvis.osim"
    motion = read_storage(shared_data / KICK / "preprocessed/IKData/drive_kick1.sto")
    coords, poses = sampling.poses_around_motion(model_file, motion, samples_per_frame=1, seed=0,
                                                 varied=COORDINATES, bridge=bridge)
    poses = poses[:7]
    whole = sampling.opensim_samples(model_file, coords, poses, COORDINATES, bridge=bridge)
    monkeypatch.setattr(sampling, "POSES_PER_CALL", 3)
    with progress_every(1e-9):  # progress on: the poses go to the worker 3 at a time
        chunked = sampling.opensim_samples(model_file, coords, poses, COORDINATES, bridge=bridge)
    np.testing.assert_array_equal(chunked.lengths, whole.lengths)
    np.testing.assert_allclose(chunked.moment_arms, whole.moment_arms, rtol=0, atol=1e-9)
    gasmed = list(whole.muscles).index("gasmed_r")
    hips = [COORDINATES.index(c) for c in COORDINATES[:3]]
    assert np.all(whole.moment_arms[:, gasmed, hips] == 0.0)
    assert np.all(np.abs(whole.moment_arms[:, gasmed, COORDINATES.index("knee_angle_r")]) > 1e-3)

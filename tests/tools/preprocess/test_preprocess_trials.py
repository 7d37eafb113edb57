"""Splitting recordings into trials, muscle-tendon velocity, the ``nmsm preprocess`` command."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.preprocess.trials import TrialSources, padding_frames, split_into_trials
from nmsm.tools.preprocess.velocity import create_velocity_file, muscle_tendon_velocity


def _write(path, time, columns, in_degrees=False):
    path.parent.mkdir(parents=True, exist_ok=True)
    write_storage(path, table_from_columns(time, columns, in_degrees=in_degrees))
    return path


@pytest.fixture
def recording(tmp_path):
    t = np.linspace(0.0, 3.0, 301)
    poly = 0.2 + 0.1 * t - 0.05 * t**3 + 0.004 * t**5  # reproduced exactly by a quintic spline
    src = tmp_path / "src"
    ik = _write(src / "ik.mot", t, {"knee_angle_r": np.rad2deg(poly), "pelvis_tx": poly}, in_degrees=True)
    inverse = _write(src / "id.sto", t, {"knee_angle_r_moment": 10 * np.sin(t)})
    emg = _write(src / "emg.sto", np.linspace(0, 3, 3001), {"Sol": np.linspace(0, 1, 3001) ** 2})
    ma = src / "MA"
    _write(ma / "x_MuscleAnalysis_Length.sto", t, {"soleus_r": 0.3 + 0.01 * np.sin(2 * np.pi * t)})
    _write(ma / "x_MuscleAnalysis_MomentArm_knee_angle_r.sto", t, {"soleus_r": 0.04 + 0 * t})
    create_velocity_file(ma / "x_MuscleAnalysis_Length.sto")
    return tmp_path, TrialSources(ik=ik, inverse_dynamics=inverse, emg=emg, muscle_analysis=ma,
                                  rotational=("knee_angle_r",)), poly


def test_split_layout_and_values(recording):
    tmp, sources, poly = recording
    names = split_into_trials([(0.5, 1.6), (1.8, 2.5)], sources, tmp / "out", prefix="gait", cutoff=None)
    assert names == ["gait_1", "gait_2"]
    ik = read_storage(tmp / "out" / "IKData" / "gait_1.sto")
    assert ik.n_rows == 101 and ik.time[0] == pytest.approx(0.5) and ik.time[-1] == pytest.approx(1.6)
    t = ik.time
    expected = 0.2 + 0.1 * t - 0.05 * t**3 + 0.004 * t**5
    assert np.abs(ik.column("knee_angle_r") - expected).max() <= 1e-9  # degrees -> radians, rotational only
    assert np.abs(ik.column("pelvis_tx") - expected).max() <= 1e-9  # translation untouched
    for k, (t0, t1) in enumerate([(0.5, 1.6), (1.8, 2.5)], start=1):
        emg = read_storage(tmp / "out" / "EMGData" / f"gait_{k}.sto")
        pad = padding_frames([(0.5, 1.6), (1.8, 2.5)])
        assert pad == math.ceil(0.2 / (0.7 / 100))  # shortest trial sets the padding
        assert emg.n_rows == 101 + 2 * pad
        assert emg.time[pad] == pytest.approx(t0) and emg.time[-pad - 1] == pytest.approx(t1)
    folder = tmp / "out" / "MAData" / "gait_2"
    assert sorted(p.name for p in folder.iterdir()) == [
        "gait_2_Length.sto", "gait_2_MomentArm_knee_angle_r.sto", "gait_2_Velocity.sto"]


def test_lowpass_before_resampling(recording):
    tmp, sources, _ = recording
    split_into_trials([(0.5, 1.6)], sources, tmp / "lp", cutoff=6.0, prefix="g")
    moment = read_storage(tmp / "lp" / "IDData" / "g_1.sto")
    assert np.abs(moment.column("knee_angle_r_moment") - 10 * np.sin(moment.time)).max() <= 1e-3


def test_bad_split_input(recording):
    tmp, sources, _ = recording
    with pytest.raises(InputError, match="start < end"):
        split_into_trials([(1.0, 0.5)], sources, tmp / "bad")
    with pytest.raises(InputError, match="covers"):
        split_into_trials([(2.5, 2.99)], sources, tmp / "bad2")  # EMG padding runs past the data
    with pytest.raises(InputError, match="no model"):
        split_into_trials([(0.5, 1.6)], TrialSources(ik=sources.ik), tmp / "bad3")


def test_velocity_is_the_derivative():
    t = np.linspace(0, 1, 201)
    lengths = table_from_columns(t, {"m": 0.3 + 0.02 * np.sin(2 * np.pi * t)})
    v = muscle_tendon_velocity(lengths, cutoff=10.0)
    exact = 0.02 * 2 * np.pi * np.cos(2 * np.pi * t)
    assert np.abs(v.column("m")[50:150] - exact[50:150]).max() <= 2e-4
    assert np.abs(muscle_tendon_velocity(lengths, cutoff=None).column("m") - exact).max() <= 1e-4


def test_preprocess_command(recording, capsys):
    from nmsm.cli import main

    tmp, sources, _ = recording
    code = main(["preprocess", "--time-pair", "0.5 1.6", "--prefix", "walk", "--emg", str(sources.emg),
                 "--id", str(sources.inverse_dynamics), "--output", str(tmp / "cli")])
    assert code == 0
    assert (tmp / "cli" / "EMGData" / "walk_1.sto").is_file() and (tmp / "cli" / "IDData" / "walk_1.sto").is_file()
    assert "walk_1" in capsys.readouterr().out


def test_muscle_analysis_through_the_model_core(shared_data, tmp_path):
    """nmsm's muscle analysis on the tutorial IK agrees with the OpenSim-made MAData.

    The stored MAData came from OpenSim's MuscleAnalysis on the full-length IK, then
    filtered and resampled; ours runs on the resampled IK: measured differences <= 1.1 mm.
    """
    from nmsm.tools.preprocess.analyses import muscle_analysis

    folder = shared_data / "preprocessing" / "uf_subject3_tutorial" / "PreCompleted"
    out = muscle_analysis(folder / "input_data" / "UF_Subject_3_reduced_muscles.osim",
                          folder / "preprocessed" / "IKData" / "gait_1.sto", tmp_path, name="gait_1",
                          coordinates=["hip_flexion_r", "knee_angle_r", "ankle_angle_r"])
    for quantity in ("Length", "MomentArm_hip_flexion_r", "MomentArm_ankle_angle_r"):
        ours = read_storage(out / f"gait_1_MuscleAnalysis_{quantity}.sto")
        theirs = read_storage(folder / "preprocessed" / "MAData" / "gait_1" / f"gait_1_{quantity}.sto")
        assert np.abs(ours.columns(theirs.labels) - theirs.data).max() <= 1.5e-3

"""Splitting recordings into trials, muscle-tendon velocity, the ``nmsm preprocess`` command."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.preprocess.trials import TrialSources, emg_windows, padding_frames, split_into_trials
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
    Knee moment arms are left out: gasmed_r's differs from OpenSim's by 17 mm (of 31 mm)
    in nmsm's model core (the other muscles' by 5e-9 m; docs/preprocess.md).
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


def test_header_row_count_is_honoured(tmp_path):
    """OpenSim's Storage keeps the header's nRows rows; so does preprocessing."""
    from nmsm.tools.preprocess.tables import read_table

    path = tmp_path / "raw.mot"
    rows = "\n".join(f"{k / 100:.2f}\t{k}" for k in range(6))
    path.write_text(f"raw\nversion=1\nnRows=5\nnColumns=2\ninDegrees=no\nendheader\ntime\tA\n{rows}\n")
    with pytest.warns(UserWarning, match="using the first 5"):
        table = read_table(path)
    assert table.n_rows == 5 and table.time[-1] == pytest.approx(0.04)


def test_ground_reaction_gaps_and_units(recording, tmp_path):
    tmp, sources, poly = recording
    t = np.linspace(0.0, 3.0, 301)
    cop = np.where((t > 1.0) & (t < 1.3), np.nan, 0.5 + 0.1 * t)
    grf = _write(tmp / "src" / "grf.mot", t, {"ground_force_1_vy": 700 + 0 * t, "ground_force_1_px": cop})
    from nmsm.io.storage import read_storage as read

    split_into_trials([(0.5, 1.6)], TrialSources(ik=sources.ik, grf=grf), tmp / "g", prefix="w", cutoff=None,
                      ik_radians=False)
    out = read(tmp / "g" / "GRFData" / "w_1.sto", allow_nan=lambda label: label.endswith("_px"))
    px = out.column("ground_force_1_px")
    inside = (out.time > 1.02) & (out.time < 1.28)
    assert np.isnan(px[inside]).all() and not np.isnan(px[~inside & (out.time < 0.99)]).any()
    assert np.abs(out.column("ground_force_1_vy") - 700).max() <= 1e-9
    ik = read(tmp / "g" / "IKData" / "w_1.sto")
    assert ik.in_degrees  # kept in the input's unit on request
    assert np.abs(ik.column("knee_angle_r") - np.rad2deg(0.2 + 0.1 * ik.time - 0.05 * ik.time**3
                                                         + 0.004 * ik.time**5)).max() <= 1e-7


def test_bad_preprocess_input(recording, tmp_path):
    from nmsm.tools.preprocess.command import preprocess
    from nmsm.tools.preprocess.run import PreprocessRequest, parse_time_pairs

    tmp, sources, _ = recording
    with pytest.raises(InputError, match="EMG column.*Gastroc.*not in the EMG file"):
        preprocess(PreprocessRequest(time_pairs=((0.5, 1.6),), output=tmp / "x", processed_emg=sources.emg,
                                     emg_channels=("Sol", "Gastroc")))
    with pytest.raises(InputError, match="ID covers 0-3 s but the trial needs 2.5-3.5 s"):
        preprocess(PreprocessRequest(time_pairs=((2.5, 3.5),), output=tmp / "y", inverse_dynamics=sources.inverse_dynamics))
    with pytest.raises(InputError, match="a model is needed"):
        preprocess(PreprocessRequest(time_pairs=((0.5, 1.6),), output=tmp / "z", compute_muscle_analysis=True,
                                     ik=sources.ik))
    with pytest.raises(InputError, match="not two numbers"):
        parse_time_pairs(["0.5 end"])
    uneven = _write(tmp / "src" / "uneven.sto", np.array([0, 0.1, 0.15, 0.4, 0.5, 0.6, 0.7, 0.9, 1.0]),
                    {"knee_angle_r_moment": np.arange(9.0)})
    with pytest.raises(InputError, match="unevenly spaced"):
        split_into_trials([(0.2, 0.8)], TrialSources(inverse_dynamics=uneven), tmp / "u")
    (tmp / "src" / "MA_empty").mkdir()
    with pytest.raises(InputError, match="no muscle-tendon length file"):
        split_into_trials([(0.5, 1.6)], TrialSources(muscle_analysis=tmp / "src" / "MA_empty"), tmp / "v")


def test_preprocess_command_from_raw_emg(shared_data, tmp_path, capsys):
    """``nmsm preprocess`` from the tutorial's raw EMG and its (JMP-trial) IK motion."""
    from nmsm.cli import main

    folder = shared_data / "preprocessing" / "uf_subject3_tutorial"
    pre = folder / "PreCompleted" / "input_data"
    with pytest.warns(UserWarning, match="nRows"):
        code = main(["preprocess", "--time-pair", "0.3 0.8", "--prefix", "gait", "--model",
                     str(pre / "UF_Subject_3_reduced_muscles.osim"), "--raw-emg",
                     str(folder / "input_data" / "GaitTrial48_EMG.mot"), "--emg-low-pass", str(3.5 / 1.1),
                     "--emg-channels", "BicFemLong GasMed Sol", "--ik", str(pre / "GaitTrial_IKResults.mot"),
                     "--output", str(tmp_path / "out")])
    assert code == 0 and "gait_1" in capsys.readouterr().out
    ik = read_storage(tmp_path / "out" / "IKData" / "gait_1.sto")
    emg = read_storage(tmp_path / "out" / "EMGData" / "gait_1.sto")
    assert ik.n_rows == 101 and not ik.in_degrees
    assert abs(ik.column("knee_angle_r")).max() < np.pi  # radians
    assert emg.labels == ("BicFemLong", "GasMed", "Sol") and emg.n_rows == 101 + 2 * 40


def test_settings_file_route(tmp_path):
    """``nmsm run`` on a ``<DataPreprocessingTool>`` file (the pipeline's stage) runs this package."""
    from nmsm.cli import main
    from nmsm.tools.preprocess.run import EmgOptions, process_emg_table

    t = np.linspace(0.0, 3.0, 301)
    data = tmp_path / "analysis"
    _write(data / "IKData" / "gait.sto", t, {"knee_angle_r": 20 + 10 * np.sin(2 * t)}, in_degrees=True)
    _write(data / "IDData" / "gait.sto", t, {"knee_angle_r_moment": 10 * np.sin(t)})
    rng = np.random.default_rng(4)
    te = np.arange(0.0, 3.0, 1e-3)
    raw = {name: (1 + np.sin(k + 3 * te)) * rng.standard_normal(te.size) for k, name in enumerate(("Sol", "TibAnt", "GasMed", "VasMed"))}
    emg = _write(data / "EMGData" / "gait.sto", te, raw)
    ma = data / "MAData" / "gait"
    _write(ma / "gait_Length.sto", t, {"soleus_r": 0.3 + 0.01 * np.sin(2 * t)})
    _write(ma / "gait_MomentArm_knee_angle_r.sto", t, {"soleus_r": 0.04 + 0 * t})
    create_velocity_file(ma / "gait_Length.sto")
    from nmsm.examples.synthetic_jmp import leg_model_xml

    # the stage reads the model: the IK header is checked against its rotational coordinates
    (tmp_path / "model.osim").write_text(leg_model_xml().decode().replace('"knee_angle"', '"knee_angle_r"'))
    settings = tmp_path / "pre.xml"
    settings.write_text('<NMSMPipelineDocument Version="1.5.3"><DataPreprocessingTool>'
                        "<results_directory>out</results_directory><input_model_file>model.osim</input_model_file>"
                        "<motion_data_directory>analysis</motion_data_directory><TrialSet><Trial name='gait'>"
                        "<time_ranges>0.5 1.6 1.8 2.6</time_ranges></Trial></TrialSet></DataPreprocessingTool>"
                        "</NMSMPipelineDocument>")
    assert main(["run", str(settings)]) == 0
    out = tmp_path / "out"
    assert sorted(p.name for p in (out / "MAData" / "gait_2").iterdir()) == [
        "gait_2_Length.sto", "gait_2_MomentArm_knee_angle_r.sto", "gait_2_Velocity.sto"]
    expected_emg = process_emg_table(read_storage(emg), EmgOptions(demean="channel"))
    check = tmp_path / "check"
    split_into_trials([(0.5, 1.6)], TrialSources(emg=expected_emg), check, names=["gait_1"], clip_emg=True)
    ours = read_storage(out / "EMGData" / "gait_1.sto")
    assert np.abs(ours.data - read_storage(check / "EMGData" / "gait_1.sto").data).max() <= 1e-12
    assert read_storage(out / "IKData" / "gait_1.sto").in_degrees  # the stage keeps the input's unit
    frame = tmp_path / "frame.xml"
    frame.write_text(settings.read_text().replace("<results_directory>out", "<emg_demean>frame</emg_demean>"
                                                  "<results_directory>out_frame"))
    assert main(["run", str(frame)]) == 0
    original = process_emg_table(read_storage(emg), EmgOptions(demean="frame"))
    split_into_trials([(0.5, 1.6)], TrialSources(emg=original), check / "frame", names=["gait_1"], clip_emg=True)
    ours = read_storage(tmp_path / "out_frame" / "EMGData" / "gait_1.sto")
    assert np.abs(ours.data - read_storage(check / "frame" / "EMGData" / "gait_1.sto").data).max() <= 1e-12


def test_velocity_made_without_touching_the_inputs(recording):
    from nmsm.tools.preprocess.command import preprocess
    from nmsm.tools.preprocess.run import PreprocessRequest

    tmp, sources, _ = recording
    ma = tmp / "src" / "MA_no_velocity"
    ma.mkdir()
    for path in sources.muscle_analysis.iterdir():
        if "Velocity" not in path.name:
            (ma / path.name).write_bytes(path.read_bytes())
    before = sorted(p.name for p in ma.iterdir())
    preprocess(PreprocessRequest(time_pairs=((0.5, 1.6),), output=tmp / "mv", muscle_analysis=ma))
    assert sorted(p.name for p in ma.iterdir()) == before
    made = read_storage(tmp / "mv" / "MAData" / "trial_1" / "trial_1_Velocity.sto")
    exact = 0.01 * 2 * np.pi * np.cos(2 * np.pi * made.time)
    assert np.abs(made.column("soleus_r") - exact).max() <= 2e-3


def test_emg_windows_padded_per_window():
    """``per_window``: each pair padded as if it were alone (the pipeline's stage, one request
    per recording); by default every pair gets the shortest pair's padding frames."""
    pairs = [(0.5, 1.6), (1.8, 2.6)]
    alone = [emg_windows([p], 101, 0.1)[0] for p in pairs]
    assert emg_windows(pairs, 101, 0.1, per_window=True) == alone
    shared = emg_windows(pairs, 101, 0.1)
    assert shared[1] == alone[1] and shared[0] != alone[0]  # the shorter pair's frames for both

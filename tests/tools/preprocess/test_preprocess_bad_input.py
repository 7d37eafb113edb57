"""Bad input to ``nmsm preprocess``: checked before processing, named by file, nothing left behind,
no mixing of runs in one output folder, never written among the inputs."""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.preprocess.trials import TrialSources, split_into_trials
from nmsm.tools.preprocess.velocity import create_velocity_file


def _write(path: Path, time, columns, in_degrees=False) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_storage(path, table_from_columns(time, columns, in_degrees=in_degrees))
    return path


@pytest.fixture
def inputs(tmp_path: Path) -> Path:
    """A recording (0-3 s): IK (degrees), ID, ground reactions, raw EMG (1 kHz), muscle analysis."""
    src = tmp_path / "input_data"
    t = np.linspace(0.0, 3.0, 301)
    _write(src / "ik.mot", t, {"knee_angle_r": 20 + 10 * np.sin(2 * t), "pelvis_tx": 0.1 * t}, in_degrees=True)
    _write(src / "id.sto", t, {"knee_angle_r_moment": 10 * np.sin(t)})
    _write(src / "grf.mot", t, {"ground_force_1_vy": 700 + 0 * t})
    te = np.arange(0.0, 3.0005, 1e-3)
    rng = np.random.default_rng(3)
    _write(src / "emg.mot", te, {name: (1.2 + np.sin(k + 3 * te)) * rng.standard_normal(te.size)
                                 for k, name in enumerate(("Sol", "TibAnt", "GasMed"))})
    ma = src / "MA"
    _write(ma / "x_MuscleAnalysis_Length.sto", t, {"soleus_r": 0.3 + 0.01 * np.sin(2 * np.pi * t)})
    _write(ma / "x_MuscleAnalysis_MomentArm_knee_angle_r.sto", t, {"soleus_r": 0.04 + 0 * t})
    create_velocity_file(ma / "x_MuscleAnalysis_Length.sto")
    return src


def _args(src: Path, out: Path, pair: str = "0.5 1.6", **only: bool) -> list[str]:
    options = {"ik": ["--ik", str(src / "ik.mot"), "--model", str(src.parent / "knee.osim")],
               "id": ["--id", str(src / "id.sto")], "grf": ["--grf", str(src / "grf.mot")],
               "emg": ["--raw-emg", str(src / "emg.mot"), "--emg-demean", "channel"],
               "ma": ["--muscle-analysis", str(src / "MA")]}
    args = ["--traceback", "preprocess", "--time-pair", pair, "--prefix", "walk", "--output", str(out)]
    for key, extra in options.items():
        if only.get(key, not only):
            args += extra
    return args


@pytest.fixture
def model(inputs: Path) -> Path:
    from nmsm.examples.synthetic_jmp import leg_model_xml

    text = leg_model_xml().decode().replace('"knee_angle"', '"knee_angle_r"')
    path = inputs.parent / "knee.osim"
    path.write_text(text)
    return path


def _snapshot(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


def test_the_whole_recording_is_written(inputs, model, tmp_path, capsys):
    out = tmp_path / "out"
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        assert main(_args(inputs, out)) == 0
    assert not record
    assert sorted(_snapshot(out)) == [
        "EMGData/walk_1.sto", "GRFData/walk_1.sto", "IDData/walk_1.sto", "IKData/walk_1.sto",
        "MAData/walk_1/walk_1_Length.sto", "MAData/walk_1/walk_1_MomentArm_knee_angle_r.sto",
        "MAData/walk_1/walk_1_Velocity.sto", "intermediate/processedEmg.sto"]


# ----- item 3: checked before processing, nothing left, the input file named -----------------
def test_time_pair_outside_the_ik_fails_before_processing(inputs, model, tmp_path, monkeypatch):
    """pre01: the IK's range is checked before the EMG is processed; nothing is written."""
    import nmsm.tools.preprocess.run as run

    monkeypatch.setattr(run, "process_emg_table", lambda *a, **k: pytest.fail("EMG processed before the check"))
    _write(inputs / "ik.mot", np.linspace(0, 1.07, 108), {"knee_angle_r": np.linspace(10, 20, 108)}, in_degrees=True)
    out = tmp_path / "out"
    with pytest.raises(InputError) as info:
        main(_args(inputs, out))
    assert str(inputs / "ik.mot") in str(info.value)
    assert "IK covers 0-1.07 s but the trial needs 0.5-1.6 s" in str(info.value)
    assert not out.exists()


def test_reversed_time_pair_fails_before_anything(inputs, model, tmp_path, monkeypatch):
    """pre02: '0.9 0.3' is refused before any file is read or processed."""
    import nmsm.tools.preprocess.command as command
    import nmsm.tools.preprocess.run as run

    for module in (command, run):
        monkeypatch.setattr(module, "read_table", lambda *a, **k: pytest.fail("input read before the argument check"))
    out = tmp_path / "out"
    with pytest.raises(InputError, match=r"--time-pair: time pair 0.9 0.3 does not increase \(expected start < end"):
        main(_args(inputs, out, "0.9 0.3"))
    assert not out.exists()


def test_emg_too_short_names_the_raw_file(inputs, tmp_path):
    """pre05: the raw EMG file is named, not the intermediate processed EMG."""
    te = np.arange(0.0, 0.4, 1e-3)
    _write(inputs / "emg.mot", te, {"Sol": np.sin(300 * te)})
    out = tmp_path / "out"
    with pytest.raises(InputError) as info:
        main(_args(inputs, out, emg=True))
    message = str(info.value)
    assert message.startswith(f"{inputs / 'emg.mot'}: EMG covers 0-0.399 s but the trial needs")
    assert "processedEmg" not in message and not out.exists()


def test_error_while_writing_leaves_the_output_folder_as_it_was(inputs, model, tmp_path):
    """An error after the first trial files were made (unevenly sampled ID) leaves nothing behind."""
    t = np.array([0, 0.1, 0.15, 0.4, 0.5, 0.6, 0.7, 0.9, 1.0, 2.0, 3.0])
    _write(inputs / "id.sto", t, {"knee_angle_r_moment": np.arange(11.0)})
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="unevenly spaced"):
        main(_args(inputs, out))
    assert _snapshot(out) == {"notes.txt": hashlib.sha256(b"mine").hexdigest()}
    assert [p.name for p in out.iterdir()] == ["notes.txt"]


def test_error_while_writing_into_a_new_folder_leaves_no_folder(inputs, model, tmp_path):
    t = np.array([0, 0.1, 0.15, 0.4, 0.5, 0.6, 0.7, 0.9, 1.0, 2.0, 3.0])
    _write(inputs / "id.sto", t, {"knee_angle_r_moment": np.arange(11.0)})
    with pytest.raises(InputError, match="unevenly spaced"):
        main(_args(inputs, tmp_path / "new" / "deeper" / "out"))
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("option, value, message", [
    ("--rows", "1", "--rows: 1 rows per trial"),
    ("--emg-padding-time", "-0.1", "--emg-padding-time: EMG padding time -0.1 s"),
    ("--prefix", "a/b", "--prefix: prefix 'a/b'"),
    ("--emg", "x.sto", "--raw-emg/--emg: both --raw-emg and --emg given"),
])
def test_bad_arguments(inputs, tmp_path, option, value, message):
    out = tmp_path / "out"
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        main(_args(inputs, out, emg=True) + [option, value])
    assert not out.exists()


# ----- item 2: no mixing of runs, never among the inputs --------------------------------------
def test_earlier_files_of_the_trial_are_refused(inputs, model, tmp_path):
    """pre09: a run writing only EMG and IK of walk_1 into a folder holding another run's walk_1
    (ID, GRF, MA of another window) is refused before anything is written."""
    out = tmp_path / "out"
    assert main(_args(inputs, out, "1.0 2.0")) == 0
    before = _snapshot(out)
    with pytest.raises(InputError) as info:
        main(_args(inputs, out, "0.5 1.6", emg=True, ik=True))
    message = str(info.value)
    assert message.startswith(f"{out}: --output: the output folder {out} already holds files of trial(s) walk_1 that this "
                              "run would not rewrite: GRFData/walk_1.sto, IDData/walk_1.sto, MAData/walk_1/")
    assert "IKData/walk_1.sto" not in message and "EMGData" not in message
    assert _snapshot(out) == before


def test_earlier_moment_arm_of_the_trial_is_refused(inputs, model, tmp_path):
    out = tmp_path / "out"
    assert main(_args(inputs, out)) == 0
    (inputs / "MA" / "x_MuscleAnalysis_MomentArm_knee_angle_r.sto").unlink()
    with pytest.raises(InputError, match="would not rewrite: MAData/walk_1/walk_1_MomentArm_knee_angle_r.sto"):
        main(_args(inputs, out))


def test_same_run_again_and_other_trials_are_accepted(inputs, model, tmp_path):
    out = tmp_path / "out"
    assert main(_args(inputs, out)) == 0
    first = read_storage(out / "IKData" / "walk_1.sto")
    assert main(_args(inputs, out, "1.0 2.0")) == 0  # every file of walk_1 rewritten
    assert read_storage(out / "IKData" / "walk_1.sto").time[0] == pytest.approx(1.0) != first.time[0]
    (out / "IKData" / "walk_10.sto").write_text("another trial")
    (out / "MAData" / "walk_10").mkdir()
    assert main(_args(inputs, out)) == 0  # walk_10 is not walk_1


def test_output_into_the_inputs_folder_is_refused(inputs, model, tmp_path, monkeypatch):
    """pre08: --output input_data (the raw inputs' folder) is refused; the folder is untouched."""
    before = _snapshot(inputs)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"--output: the output folder input_data holds the input .*emg.mot "
                                         r"\(--raw-emg\)"):
        main(_args(Path("input_data"), Path("input_data")))
    with pytest.raises(InputError, match=r"the output folder input_data/MA is the input folder"):
        main(_args(Path("input_data"), Path("input_data/MA"), ma=True))
    assert _snapshot(inputs) == before


# ----- item 6: a wrong nRows: the first nRows rows, as the original, the raw file named ------
def test_short_row_count_in_the_raw_emg_names_the_raw_file(inputs, tmp_path):
    """pre05: nRows=400 on a 3001-row raw EMG: the first 400 rows, as OpenSim's Storage (and so
    the original) reads them, with a warning; the trial then lies beyond them and the error names
    the raw EMG file (not an intermediate output); nothing is written."""
    path = inputs / "emg.mot"
    path.write_text(path.read_text().replace("nRows=3001", "nRows=400"))
    out = tmp_path / "out"
    with pytest.warns(UserWarning, match=f"{path}: header says nRows=400, file has 3001 rows; using the first 400"):
        with pytest.raises(InputError, match=f"{path}: EMG covers 0-0.399 s but the trial needs"):
            main(_args(inputs, out, emg=True))
    assert not out.exists()


# ----- item 4: the IK header against the model ------------------------------------------------
def test_ik_in_degrees_marked_radians_warns(inputs, model, tmp_path):
    """pre04: a degrees IK file saying inDegrees=no is named with the column and both units."""
    path = inputs / "ik.mot"
    path.write_text(path.read_text().replace("inDegrees=yes", "inDegrees=no"))
    with pytest.warns(UserWarning, match=rf"{path}: read with inDegrees=no, rotational column\(s\) 'knee_angle_r' "
                                         r"10..30 rad \(573\d?..1719 deg\), outside \[-2π, 2π\] rad.*header may be "
                                         r"wrong \(inDegrees=yes\)"):
        main(_args(inputs, tmp_path / "out", ik=True))


def test_split_warns_on_a_radians_ik_marked_degrees(tmp_path):
    t = np.linspace(0.0, 3.0, 301)
    ik = _write(tmp_path / "ik.mot", t, {"knee_angle_r": -0.6 + 0.5 * np.sin(2 * t)}, in_degrees=True)
    with pytest.warns(UserWarning, match="look like radians, the header may be wrong"):
        split_into_trials([(0.5, 1.6)], TrialSources(ik=ik, rotational={"knee_angle_r": (-2.1, 0.17)}), tmp_path / "o")


def test_tutorial_inputs_are_silent_but_for_the_emg_row_count(shared_data, tmp_path):
    """The tutorial's raw EMG, IK (degrees) and model: only the raw EMG's nRows=4000 (4001 rows)
    warns (its first 4000 rows are used, as the original: test_preprocess_emg.py)."""
    folder = shared_data / "preprocessing" / "uf_subject3_tutorial"
    pre = folder / "PreCompleted" / "input_data"
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        code = main(["preprocess", "--time-pair", "0.3 0.8", "--prefix", "gait", "--model",
                     str(pre / "UF_Subject_3_reduced_muscles.osim"), "--raw-emg",
                     str(folder / "input_data" / "GaitTrial48_EMG.mot"), "--emg-low-pass", str(3.5 / 1.1),
                     "--ik", str(pre / "GaitTrial_IKResults.mot"), "--output", str(tmp_path / "out")])
    assert code == 0
    assert sorted({str(w.message) for w in record}) == [  # the raw EMG is read by the checks and by the run
        f"{folder / 'input_data' / 'GaitTrial48_EMG.mot'}: header says nRows=4000, file has 4001 rows; "
        "using the first 4000 as OpenSim's Storage (and so the original) does"]

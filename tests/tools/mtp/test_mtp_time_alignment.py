"""MTP pairs the rows of IDData, MAData and EMGData by position (as the original): a file of
another time window is an error naming it, a constant offset of every file or a 1e-6 s jitter
is not. (An EMG file shifted by 0.05 s used to give a result, its EMG paired with moments
50 ms away.)"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage
from nmsm.tools.mtp.mtli import load_passive_trials
from nmsm.tools.mtp.run import run_settings
from test_mtp_bad_input import write_settings as _settings  # the same short tutorial run


def _shift_times(path: Path, change) -> None:
    """Rewrite the time column of an OpenSim table with ``change(times)`` (text edit, rest untouched)."""
    lines = path.read_text().splitlines()
    end = next(i for i, line in enumerate(lines) if line.strip().lower() == "endheader") + 2
    rows = [line.split("\t") for line in lines[end:] if line.strip()]
    times = change(np.array([float(row[0]) for row in rows]))
    lines[end:] = ["\t".join([repr(float(t)), *row[1:]]) for t, row in zip(times, rows)]
    path.write_text("\n".join(lines) + "\n")


def test_emg_of_another_time_window_is_an_error(case):
    folder, tutorial = case
    emg = folder / "preprocessed" / "EMGData" / "gait_1.sto"
    _shift_times(emg, lambda t: t + 0.05)
    with pytest.raises(InputError) as info:
        run_settings(_settings(folder, tutorial), accept_unconverged=True)
    message = str(info.value)
    assert str(emg) in message and "column 'time'" in message
    assert "data row 20 (ID row 1; 19 padding rows before it) is at 0.55 s but IDData/gait_1.sto is at 0.5 s" in message
    assert not (folder / "results").exists()


def test_muscle_analysis_of_other_frames_is_an_error(case):
    folder, tutorial = case
    velocity = folder / "preprocessed" / "MAData" / "gait_1" / "gait_1_Velocity.sto"
    _shift_times(velocity, lambda t: t - t[0])  # the same frames exported from 0 s
    with pytest.raises(InputError, match=r"gait_1_Velocity.sto: column 'time': trial 'gait_1': data row 1 is at 0.0 s"):
        run_settings(_settings(folder, tutorial), accept_unconverged=True)
    arm = folder / "preprocessed" / "MAData" / "gait_1" / "gait_1_MomentArm_knee_angle_r.sto"
    _shift_times(velocity, lambda t: t + 0.5)  # back to the ID's times
    _shift_times(arm, lambda t: t + 0.011)  # one frame late
    with pytest.raises(InputError, match=r"gait_1_MomentArm_knee_angle_r.sto: column 'time'"):
        run_settings(_settings(folder, tutorial), accept_unconverged=True)


def test_offset_of_every_file_gives_the_same_result(case, tmp_path_factory, shared_data):
    folder, tutorial = case
    plain = tmp_path_factory.mktemp("plain")
    shutil.copytree(tutorial / "preprocessed", plain / "preprocessed")
    run_settings(_settings(plain, tutorial), accept_unconverged=True)
    for path in (folder / "preprocessed").rglob("*.sto"):
        if path.parent.name != "IKData":
            _shift_times(path, lambda t: t + 10.0)
    run_settings(_settings(folder, tutorial), accept_unconverged=True)
    name = "muscleActivations/gait_1_muscleActivations.sto"
    expected, got = read_storage(plain / "results" / name), read_storage(folder / "results" / name)
    np.testing.assert_allclose(got.time, expected.time + 10.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.data, expected.data, rtol=0, atol=1e-9)


def test_passive_trial_moment_arms_of_other_frames_are_an_error(tmp_path, shared_data):
    source = shared_data / "mtp" / "uf_subject3_tutorial" / "passive_moment_data"
    shutil.copytree(source, tmp_path / "passive")
    muscles = ["soleus_r", "gasmed_r"]
    assert len(load_passive_trials(tmp_path / "passive", ["ankle_angle_r"], muscles)) == 12
    arm = tmp_path / "passive" / "MAData" / "Thelen_AnklePassive_02" / "Thelen_AnklePassive_02_MuscleAnalysis_MomentArm_ankle_angle_r.sto"
    _shift_times(arm, lambda t: t + 0.2)
    with pytest.raises(InputError, match="Thelen_AnklePassive_02_MuscleAnalysis_MomentArm_ankle_angle_r.sto: column 'time'"):
        load_passive_trials(tmp_path / "passive", ["ankle_angle_r"], muscles)


def test_times_in_milliseconds_are_an_error(case):
    folder, tutorial = case
    for path in (folder / "preprocessed").rglob("*.sto"):
        _shift_times(path, lambda t: t * 1000.0)
    with pytest.raises(InputError, match=r"EMGData/gait_1.sto: column 'time': the EMG sample interval is 11 s: "
                                         r"are the times in milliseconds\?"):
        run_settings(_settings(folder, tutorial), accept_unconverged=True)


def _edit_column(path: Path, label: str, change) -> None:
    lines = path.read_text().splitlines()
    end = next(i for i, line in enumerate(lines) if line.strip().lower() == "endheader") + 1
    j = lines[end].split("\t").index(label)
    for i in range(end + 1, len(lines)):
        cells = lines[i].split("\t")
        cells[j] = repr(change(i - end - 1, float(cells[j])))
        lines[i] = "\t".join(cells)
    path.write_text("\n".join(lines) + "\n")


def test_dead_and_negative_emg_channels_warn(case):
    folder, tutorial = case
    emg = folder / "preprocessed" / "EMGData" / "gait_1.sto"
    _edit_column(emg, "GasMed", lambda i, v: 0.0)
    _edit_column(emg, "TibAnt", lambda i, v: -0.25 if i == 40 else v)
    with pytest.warns(UserWarning) as record:
        run_settings(_settings(folder, tutorial), accept_unconverged=True)
    messages = [str(w.message) for w in record]
    assert any(f"{emg}: EMG channel(s) GasMed have the same value in every row" in m for m in messages)
    assert any(f"{emg}: column 'TibAnt': processed EMG reaches -0.25 at 0.731 s (1 row(s) below -0.01)" in m
               for m in messages)


def test_tutorial_emg_is_silent(case):
    import warnings

    folder, tutorial = case
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        run_settings(_settings(folder, tutorial), accept_unconverged=True)
    assert not [w for w in record if "EMG" in str(w.message) and "gait_1.sto" in str(w.message)]


def test_emg_at_another_rate_says_so(case):
    folder, tutorial = case
    emg = folder / "preprocessed" / "EMGData" / "gait_1.sto"
    table = read_storage(emg)
    fine = np.linspace(table.time[0], table.time[-1], 2 * table.n_rows - 1)  # twice the ID rate: 277 rows
    from nmsm.io.storage import table_from_columns, write_storage

    write_storage(emg, table_from_columns(fine, {k: np.interp(fine, table.time, table.column(k)) for k in table.labels}))
    with pytest.raises(InputError, match=r"it is sampled every 0.0055 s, IDData/gait_1.sto every 0.011 s \(resample it"):
        run_settings(_settings(folder, tutorial), accept_unconverged=True)


def test_round_off_jitter_is_not_an_error_but_a_third_of_a_frame_is():
    """The tolerance is a quarter of the ID file's median sample interval (MAData from OpenSim
    prints its times rounded differently than the ID file)."""
    from nmsm.io.storage import Table
    from nmsm.tools.mtp.data import check_same_times

    time = 0.5 + 0.011 * np.arange(101)
    reference = Table(time=time, labels=(), data=np.zeros((101, 0)), source=Path("IDData/gait_1.sto"))

    def other(times):
        return Table(time=times, labels=(), data=np.zeros((times.size, 0)), source=Path("MAData/x.sto"))

    check_same_times(reference, other(time + 1e-6 * (-1.0) ** np.arange(101)), "gait_1")
    check_same_times(reference, other(time + 0.24 * 0.011), "gait_1")
    with pytest.raises(InputError, match="data row 1 is at"):
        check_same_times(reference, other(time + 0.3 * 0.011), "gait_1")


def test_emg_alone_in_milliseconds_asks_about_the_unit(case):
    """Only the EMG file in ms (ID in s): the sampling-rate hint said 'resample it to the ID
    frames'; a step 1000 times the ID's is a unit, not a rate."""
    folder, tutorial = case
    emg = folder / "preprocessed" / "EMGData" / "gait_1.sto"
    _shift_times(emg, lambda t: t * 1000.0)
    with pytest.raises(InputError) as info:
        run_settings(_settings(folder, tutorial), accept_unconverged=True)
    message = str(info.value)
    assert str(emg) in message and "are its times in milliseconds?" in message and "resample" not in message

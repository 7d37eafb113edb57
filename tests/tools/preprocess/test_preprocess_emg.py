"""EMG processing (the original's processEmg), MATLAB filtfilt, and the tutorial's raw EMG.

Reference: ``data/GaitTrial_EMG_Processed_rows.sto`` holds 14 rows (both ends and the
start of the gait trial's padded window) of the original's own output of
``processRawEmgFile`` on the tutorial's raw EMG (nmsm-tutorial commit 016ed536,
``Step-2-Data-Preprocessing/input_data/GaitTrial_EMG_Processed.mot``, made with
``filterOrder 4, highPassCutoff 40, lowPassCutoff 3.5/1.1``), copied verbatim.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.signal import butter, filtfilt

from nmsm.errors import InputError
from nmsm.io.storage import read_storage
from nmsm.tools.preprocess.emg import matlab_filtfilt, process_emg, sampling_rate

REFERENCE = Path(__file__).parent / "data" / "GaitTrial_EMG_Processed_rows.sto"
TUTORIAL_LOW_PASS = 3.5 / 1.1


def test_filtfilt_uses_matlab_edge_padding():
    rng = np.random.default_rng(0)
    x = rng.standard_normal((400, 3)).cumsum(axis=0)
    b, a = butter(4, 0.08)
    ours = matlab_filtfilt(b, a, x)
    # MATLAB: odd reflection of 3 (max(len(a), len(b)) - 1) samples (scipy pads 3 max(...) by default)
    same = filtfilt(b, a, x, axis=0, padtype="odd", padlen=3 * (max(len(a), len(b)) - 1))
    assert np.abs(ours - same).max() <= 1e-12
    assert np.abs(ours - filtfilt(b, a, x, axis=0)).max() > 1e-3  # scipy's default padding differs


def test_sampling_rate_is_samples_over_duration():
    t = np.linspace(0.0, 4.0, 4001)
    assert sampling_rate(t) == pytest.approx(4001 / 4.0)


def _matlab_process_emg(time, data, order, high, low):
    """The original's processEmg written literally (channels x frames, MATLAB reductions)."""
    e = np.asarray(data, dtype=float).T  # channels x frames
    fs = len(time) / (time[-1] - time[0])
    b, a = butter(order, 2 * high / fs, "high")
    e = matlab_filtfilt(b, a, e.T).T
    e = e - np.ones((e.shape[0], 1)) @ e.mean(axis=0, keepdims=True)  # mean(emgData): along dim 1
    e = np.abs(e)
    b, a = butter(order, 2 * low / fs, "low")
    e = matlab_filtfilt(b, a, e.T).T
    e[e < 0] = 0
    e = e - np.ones((e.shape[0], 1)) @ e.min(axis=0, keepdims=True)
    e = e / e.max(axis=1, keepdims=True)
    return e.T


def test_frame_demeaning_is_the_originals_array_layout():
    rng = np.random.default_rng(3)
    t = np.arange(0, 2.0, 1e-3)
    raw = rng.standard_normal((t.size, 6)) * (1 + np.sin(np.pi * t)[:, None] * np.arange(1, 7))
    ours = process_emg(t, raw, low_pass_cutoff=6.0)
    assert np.abs(ours - _matlab_process_emg(t, raw, 4, 40.0, 6.0)).max() <= 1e-12
    per_channel = process_emg(t, raw, low_pass_cutoff=6.0, demean="channel")
    assert np.abs(ours - per_channel).max() > 1e-2  # the two modes differ


def test_processed_emg_is_a_normalized_envelope():
    fs = 1000.0
    t = np.arange(0, 3.0, 1 / fs)
    rng = np.random.default_rng(1)
    envelope = np.clip(np.sin(np.pi * t / 1.5), 0, None) ** 2
    raw = np.column_stack([envelope * rng.standard_normal(t.size), 0.3 * envelope * rng.standard_normal(t.size)])
    raw += 2.0  # DC offset removed by the high-pass
    out = process_emg(t, raw, demean="channel")
    assert out.shape == raw.shape
    assert np.allclose(out.max(axis=0), 1.0) and np.allclose(out.min(axis=0), 0.0)
    # the envelope follows the amplitude: correlated with the true envelope
    for j in range(2):
        assert np.corrcoef(out[:, j], envelope)[0, 1] > 0.95
    # channel scale does not matter after normalization
    assert np.corrcoef(out[:, 0], out[:, 1])[0, 1] > 0.9


def test_bad_emg_input():
    t = np.linspace(0, 1, 1001)
    noise = np.random.default_rng(2).standard_normal(t.size)
    with pytest.raises(InputError, match="'Flat' carry no signal"):
        process_emg(t, np.column_stack([np.sin(40 * t) * noise, np.ones(t.size)]), demean="channel",
                    labels=("Sol", "Flat"))
    with pytest.raises(InputError, match="Nyquist"):
        process_emg(t, np.column_stack([noise, noise]), low_pass_cutoff=900.0)
    with pytest.raises(InputError, match="several EMG channels"):
        process_emg(t, noise[:, None])
    with pytest.raises(InputError, match="demean mode"):
        process_emg(t, np.column_stack([noise, noise]), demean="median")


def test_tutorial_raw_emg_reproduces_the_originals_processed_emg(shared_data, tmp_path):
    """The tutorial's raw EMG through ``nmsm``'s processRawEmgFile vs the original's output.

    Measured: max |difference| 5.9e-9 over the 14 reference rows x 28 channels (ends
    included, so MATLAB's filtfilt edge padding is reproduced). Reading all 4001 rows of
    the file instead of the header's ``nRows=4000`` (what OpenSim's Storage keeps) gives
    2.3e-4 at the first row and 8.2e-3 at the last.
    """
    from nmsm.tools.preprocess.run import EmgOptions, process_raw_emg_file

    raw = shared_data / "preprocessing" / "uf_subject3_tutorial" / "input_data" / "GaitTrial48_EMG.mot"
    with pytest.warns(UserWarning, match="nRows=4000"):
        out = process_raw_emg_file(raw, tmp_path / "emg.sto", EmgOptions(low_pass_cutoff=TUTORIAL_LOW_PASS))
    ours = read_storage(out)
    reference = read_storage(REFERENCE)
    assert ours.labels == reference.labels and ours.n_rows == 4000
    rows = np.rint(reference.time * 1000).astype(int)
    assert np.abs(ours.time[rows] - reference.time).max() <= 1e-12
    assert np.abs(ours.data[rows] - reference.data).max() <= 1e-8
    with pytest.warns(UserWarning, match="using the rows"):
        all_rows = read_storage(raw)  # 4001 rows: not what the original processed
    wrong = process_emg(all_rows.time, all_rows.data, low_pass_cutoff=TUTORIAL_LOW_PASS)
    assert np.abs(wrong[rows] - reference.data).max() > 1e-4


def test_tutorial_emg_trial_layout(shared_data, tmp_path):
    """Processed EMG split like ``PreCompleted/preprocessed/EMGData/gait_1.sto``.

    Reproduced: channel set, 19 padding frames, the 139-row time grid (1e-12), and the
    values where the grid meets the original's samples (0.302 s: the spline interpolates).
    Not the stored file's values: it was made in 2022 (OpenSim 4.4) from another processed
    EMG (``Full_EMG.mot``, not in the snapshot): at 0.302 s the original's current processed
    EMG of the same recording (the reference rows) differs from it by up to 0.28, and our
    whole trial by up to 0.61 (median 0.10; docs/preprocess.md).
    """
    from nmsm.tools.preprocess.run import EmgOptions, process_raw_emg_file
    from nmsm.tools.preprocess.trials import TrialSources, padding_frames, split_into_trials

    folder = shared_data / "preprocessing" / "uf_subject3_tutorial"
    with pytest.warns(UserWarning, match="nRows"):
        processed = process_raw_emg_file(folder / "input_data" / "GaitTrial48_EMG.mot", tmp_path / "emg.sto",
                                         EmgOptions(low_pass_cutoff=TUTORIAL_LOW_PASS))
    assert padding_frames([(0.5, 1.6)]) == 19
    split_into_trials([(0.5, 1.6)], TrialSources(emg=processed), tmp_path / "out", prefix="gait")
    ours = read_storage(tmp_path / "out" / "EMGData" / "gait_1.sto")
    expected = read_storage(folder / "PreCompleted" / "preprocessed" / "EMGData" / "gait_1.sto")
    assert ours.labels == expected.labels
    assert ours.n_rows == expected.n_rows == 139
    assert np.abs(ours.time - expected.time).max() <= 1e-12
    reference = read_storage(REFERENCE)
    k = int(np.argmin(np.abs(reference.time - 0.302)))
    assert np.abs(ours.data[1] - reference.data[k]).max() <= 1e-8

"""The preprocessing stage: full-length trials cut into the personalization tools' trials
(``<DataPreprocessingTool>``, tools.md §2: ``processRawEmgFile`` and ``splitIntoTrials``).

Per full-length trial ``<name>`` and each time window ``k`` (output trial ``<name>_<k>``):

* EMG (``EMGData/<name>.sto``, raw): 4th-order Butterworth high-pass (40 Hz) with zero
  phase, column mean removed, rectified, low-pass (10 Hz) with zero phase, negatives set to
  0, column minimum subtracted, divided by the column maximum (over the whole recording);
* IK, ID, muscle-tendon lengths and moment arms: low-pass (``cutoff_frequency``, zero
  phase, on de-meaned data), then resampled by the interpolating quintic spline (OpenSim's
  GCV spline with zero error variance) to ``rows_per_trial`` rows on the window;
  muscle-tendon velocities and ground reactions resampled without filtering (ground-reaction
  centre-of-pressure gaps stay gaps: linear interpolation over the valid samples, NaN only
  between two NaN samples);
* EMG resampled on the window widened by ``pad = ceil(emg_padding_time / dt)`` rows of
  ``dt = window / (rows - 1)`` each side (``rows + 2 pad`` rows); the spline's small
  undershoots below 0 are set to 0.

Rotational IK columns are written in degrees (``inDegrees=yes``) as the input was.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np
from scipy.signal import butter, filtfilt

from nmsm.core.results import ResultsDirectory
from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage, write_storage
from nmsm.model.signal import quintic_spline
from nmsm.tools.pipeline.native import read_native_settings
from nmsm.tools.pipeline.preprocess_settings import TOOL, DataPreprocessingSettings, PreprocessTrial


def read_settings(path: str | os.PathLike[str]) -> DataPreprocessingSettings:
    return read_native_settings(path, DataPreprocessingSettings, TOOL)


def _rate(table: Table) -> float:
    return (table.n_rows - 1) / float(table.time[-1] - table.time[0])


def lowpass(table: Table, cutoff: float, order: int) -> np.ndarray:
    """Zero-phase Butterworth low-pass of the de-meaned columns (mean added back)."""
    nyquist = 0.5 * _rate(table)
    if cutoff >= nyquist:
        return table.data.copy()
    b, a = butter(order, cutoff / nyquist)
    mean = table.data.mean(axis=0, keepdims=True)
    return filtfilt(b, a, table.data - mean, axis=0) + mean


def process_emg(table: Table, high_pass: float, low_pass: float, order: int) -> np.ndarray:
    """Normalized EMG envelopes (n, channels) in [0, 1] (module docstring)."""
    nyquist = 0.5 * _rate(table)
    if not high_pass < nyquist or not low_pass < nyquist:
        raise InputError(f"EMG sampled at {2 * nyquist:g} Hz is too slow for the filters", file=table.source,
                         expected=f"a rate above {2 * max(high_pass, low_pass):g} Hz")
    b, a = butter(order, high_pass / nyquist, btype="high")
    signal = filtfilt(b, a, table.data, axis=0)
    signal = np.abs(signal - signal.mean(axis=0, keepdims=True))
    b, a = butter(order, low_pass / nyquist)
    envelope = np.maximum(filtfilt(b, a, signal, axis=0), 0.0)
    envelope -= envelope.min(axis=0, keepdims=True)
    peak = envelope.max(axis=0, keepdims=True)
    return envelope / np.where(peak > 0, peak, 1.0)


def resample(time: np.ndarray, data: np.ndarray, times: np.ndarray, source: Path | None) -> np.ndarray:
    """Interpolating quintic spline of ``data`` (n, k) at ``times`` (inside ``time``)."""
    if times[0] < time[0] - 1e-9 or times[-1] > time[-1] + 1e-9:
        raise InputError(f"data cover {time[0]:g}-{time[-1]:g} s, the trial needs {times[0]:g}-{times[-1]:g} s",
                         file=source, element="time", expected="a time range inside the recording")
    return quintic_spline(time, data, np.clip(times, time[0], time[-1]))[0]


def _linear_with_gaps(time: np.ndarray, data: np.ndarray, times: np.ndarray) -> np.ndarray:
    out = np.empty((times.size, data.shape[1]))
    right = np.clip(np.searchsorted(time, times), 0, time.size - 1)
    left = np.clip(right - 1, 0, time.size - 1)
    for j in range(data.shape[1]):
        column = data[:, j]
        valid = ~np.isnan(column)
        if valid.all():
            out[:, j] = np.interp(times, time, column)
            continue
        if not valid.any():
            out[:, j] = np.nan
            continue
        # a gap edge takes the valid neighbour's value; inside a gap the point stays undefined
        out[:, j] = np.interp(times, time[valid], column[valid])
        out[~valid[left] & ~valid[right], j] = np.nan
    return out


def _table(like: Table, times: np.ndarray, data: np.ndarray) -> Table:
    return Table(time=times, labels=like.labels, data=data, in_degrees=like.in_degrees, name=like.name,
                 comments=like.comments)


def _cut(settings: DataPreprocessingSettings, trial: PreprocessTrial, window: tuple[float, float], name: str,
         stage: Path) -> None:
    source = settings.motion_data_directory
    rows = settings.rows_per_trial
    times = np.linspace(window[0], window[1], rows)
    cutoff, order = settings.cutoff_frequency, settings.filter_order
    for folder in ("IKData", "IDData"):
        path = source / folder / f"{trial.name}.sto"
        if path.is_file():
            table = read_storage(path)
            (stage / folder).mkdir(exist_ok=True)
            data = resample(table.time, lowpass(table, cutoff, order), times, path)
            write_storage(stage / folder / f"{name}.sto", _table(table, times, data))
    grf = source / "GRFData" / f"{trial.name}.sto"
    if grf.is_file():
        table = read_storage(grf, allow_nan=lambda label: label.endswith(("px", "py", "pz")))
        (stage / "GRFData").mkdir(exist_ok=True)
        write_storage(stage / "GRFData" / f"{name}.sto",
                      _table(table, times, _linear_with_gaps(table.time, table.data, times)))
    ma = source / "MAData" / trial.name
    if ma.is_dir():
        out = stage / "MAData" / name
        out.mkdir(parents=True, exist_ok=True)
        for file in sorted(ma.glob(f"{trial.name}_*.sto")):
            table = read_storage(file)
            quantity = file.stem[len(trial.name) + 1:]
            data = table.data if quantity == "Velocity" else lowpass(table, cutoff, order)
            write_storage(out / f"{name}_{quantity}.sto", _table(table, times, resample(table.time, data, times, file)),
                          name=quantity)
    emg = source / "EMGData" / f"{trial.name}.sto"
    if emg.is_file():
        table = read_storage(emg)
        envelope = process_emg(table, settings.emg_high_pass_frequency, settings.emg_low_pass_frequency, order)
        step = (window[1] - window[0]) / (rows - 1)
        pad = math.ceil(settings.emg_padding_time / step - 1e-9)
        padded = window[0] - pad * step + step * np.arange(rows + 2 * pad)
        (stage / "EMGData").mkdir(exist_ok=True)
        resampled = np.clip(resample(table.time, envelope, padded, emg), 0.0, None)  # spline undershoot
        write_storage(stage / "EMGData" / f"{name}.sto", _table(table, padded, resampled), name="EMG")


def run_settings(settings_file: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
                 **options: Any) -> Path:
    """Run the preprocessing stage of a ``<DataPreprocessingTool>`` settings file; returns
    the output data folder."""
    settings = read_settings(settings_file)
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    results = ResultsDirectory(settings.results_directory)
    for trial in settings.trials:
        if not (settings.motion_data_directory / "IKData" / f"{trial.name}.sto").is_file() and not (
                settings.motion_data_directory / "IDData" / f"{trial.name}.sto").is_file():
            raise InputError(f"no IKData or IDData file for trial '{trial.name}'", file=settings_file,
                             element=f"<Trial name=\"{trial.name}\">",
                             expected=f"{settings.motion_data_directory}/IKData/{trial.name}.sto")
        pairs = trial.time_ranges
        for k in range(0, len(pairs), 2):
            name = f"{trial.name}_{k // 2 + 1}"
            with results.task(name) as stage:
                _cut(settings, trial, (pairs[k], pairs[k + 1]), name, stage)
    results.copy_in(settings_file, f"settings_{Path(settings_file).name}")
    return results.path

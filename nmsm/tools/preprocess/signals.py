"""Low-pass filtering and resampling of data tables (the original's ``lowpassFilter`` and GCV splines).

* :func:`lowpass`: the original's ``lowpassFilter``: Butterworth (order 4 unless given)
  with MATLAB ``filtfilt`` on each de-meaned column, mean added back (cut-off in Hz, time in
  s); sampling rate ``1 / (t(2) - t(1))`` as ``lowpassFilter`` takes it (the EMG chain
  uses ``n / (t_end - t_0)`` instead, :func:`~nmsm.tools.preprocess.emg.sampling_rate`).
* :func:`resample`: OpenSim ``GCVSplineSet`` of degree 5 with zero error variance = the
  natural quintic interpolating spline (:func:`nmsm.model.signal.quintic_spline`),
  evaluated at new times; times outside the data are an error (the original gets NaN).
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np
from scipy.signal import butter

from nmsm.errors import InputError
from nmsm.io.storage import Table
from nmsm.model.signal import quintic_spline
from nmsm.tools.preprocess.emg import matlab_filtfilt


def lowpass(time: np.ndarray, data: np.ndarray, cutoff: float, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass of each column of ``data`` (n, k) at ``cutoff`` Hz."""
    x = np.asarray(data, dtype=float)
    t = np.asarray(time, dtype=float)
    if t.size < 2 or not t[1] > t[0]:
        raise InputError("time does not increase", element="time", expected="increasing sample times")
    fs = 1.0 / (t[1] - t[0])
    steps = np.diff(t)
    if np.abs(steps - steps[0]).max() > 0.01 * steps[0]:
        raise InputError(f"samples are unevenly spaced ({steps.min():g}-{steps.max():g} s)", element="time",
                         expected="evenly sampled data to low-pass filter")
    if not 0 < cutoff < fs / 2:
        raise InputError(f"low-pass cut-off {cutoff} Hz", element="cutoff frequency",
                         expected=f"between 0 and {fs / 2:g} Hz (Nyquist)")
    b, a = butter(order, 2.0 * cutoff / fs, "low")
    mean = x.mean(axis=0)
    return matlab_filtfilt(b, a, x - mean) + mean


def check_covers(time: np.ndarray, windows: Sequence[tuple[float, float]], *, what: str,
                 file: str | os.PathLike[str] | None) -> None:
    """:class:`InputError` naming ``file`` when the samples ``time`` (s) do not span every
    window ``(start, end)`` (s; 1e-9 relative slack)."""
    lo, hi = float(time[0]), float(time[-1])
    tol = 1e-9 * max(1.0, abs(hi))
    for start, end in windows:
        if start < lo - tol or end > hi + tol:
            raise InputError(
                f"{what} covers {lo:g}-{hi:g} s but the trial needs {start:g}-{end:g} s",
                file=file,
                expected="data spanning every time pair (EMG: the pair widened by the padding)",
            )


def resample(table: Table, times: np.ndarray, *, what: str = "table") -> np.ndarray:
    """Natural quintic spline of every column of ``table`` evaluated at ``times`` (m,): (m, k)."""
    t = np.asarray(times, dtype=float)
    check_covers(table.time, [(t[0], t[-1])], what=what, file=table.source)
    lo, hi = table.time[0], table.time[-1]
    values, _, _ = quintic_spline(table.time, table.data, np.clip(t, lo, hi))
    return values


def resample_with_gaps(time: np.ndarray, data: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``data`` (n, k) at ``times`` (m,) keeping NaN gaps (m, k).

    For ground-reaction centre-of-pressure columns, NaN while the foot is off the plate: a
    time next to a gap takes the valid neighbour's value, a time between two NaN samples
    stays NaN, so the swing phase never mixes into the stance values.
    """
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
        out[:, j] = np.interp(times, time[valid], column[valid])
        out[~valid[left] & ~valid[right], j] = np.nan
    return out

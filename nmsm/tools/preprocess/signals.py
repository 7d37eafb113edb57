"""Low-pass filtering and resampling of data tables (the original's ``lowpassFilter`` and GCV splines).

* :func:`lowpass`: Butterworth (order 4 unless given) with MATLAB ``filtfilt`` on each
  de-meaned column, mean added back (cut-off in Hz, time in s).
* :func:`resample`: OpenSim ``GCVSplineSet`` of degree 5 with zero error variance = the
  natural quintic interpolating spline (:func:`nmsm.model.signal.quintic_spline`),
  evaluated at new times; times outside the data are an error (the original gets NaN).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import butter

from nmsm.errors import InputError
from nmsm.io.storage import Table
from nmsm.model.signal import quintic_spline
from nmsm.tools.preprocess.emg import matlab_filtfilt, sampling_rate


def lowpass(time: np.ndarray, data: np.ndarray, cutoff: float, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass of each column of ``data`` (n, k) at ``cutoff`` Hz."""
    x = np.asarray(data, dtype=float)
    fs = sampling_rate(time)
    if not 0 < cutoff < fs / 2:
        raise InputError(f"low-pass cut-off {cutoff} Hz", element="cutoff frequency",
                         expected=f"between 0 and {fs / 2:g} Hz (Nyquist)")
    b, a = butter(order, 2.0 * cutoff / fs, "low")
    mean = x.mean(axis=0)
    return matlab_filtfilt(b, a, x - mean) + mean


def resample(table: Table, times: np.ndarray, *, what: str = "table") -> np.ndarray:
    """Natural quintic spline of every column of ``table`` evaluated at ``times`` (m,): (m, k)."""
    t = np.asarray(times, dtype=float)
    lo, hi = table.time[0], table.time[-1]
    tol = 1e-9 * max(1.0, abs(hi))
    if t[0] < lo - tol or t[-1] > hi + tol:
        raise InputError(
            f"{what} covers {lo:g}-{hi:g} s but the trial needs {t[0]:g}-{t[-1]:g} s",
            file=table.source,
            expected="data spanning every time pair (EMG: the pair widened by the padding)",
        )
    values, _, _ = quintic_spline(table.time, table.data, np.clip(t, lo, hi))
    return values

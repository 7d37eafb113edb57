"""Zero-phase Butterworth low-pass of evenly sampled columns (the original's ``lowpassFilter``).

Each column is de-meaned, filtered forward and backward (``filtfilt``, odd padding of
``3 (max(len(a), len(b)) - 1)`` samples as MATLAB's ``filtfilt``) and the mean added back.
``time`` (T,) s; ``data`` (T,) or (T, k).
"""

from __future__ import annotations

import numpy as np
import scipy.signal


def lowpass(time: np.ndarray, data: np.ndarray, order: int, cutoff_hz: float) -> np.ndarray:
    """``data`` low-pass filtered at ``cutoff_hz`` with an ``order`` Butterworth, zero phase."""
    values = np.asarray(data, dtype=float)
    column = values.ndim == 1
    values = values[:, None] if column else values
    rate = 1.0 / float(np.mean(np.diff(np.asarray(time, dtype=float))))
    normalized = min(cutoff_hz / (rate / 2.0), 0.99)
    b, a = scipy.signal.butter(order, normalized)
    pad = 3 * (max(len(a), len(b)) - 1)
    if values.shape[0] <= pad:
        return values[:, 0].copy() if column else values.copy()
    mean = values.mean(axis=0)
    out = scipy.signal.filtfilt(b, a, values - mean, axis=0, padtype="odd", padlen=pad) + mean
    return out[:, 0] if column else out

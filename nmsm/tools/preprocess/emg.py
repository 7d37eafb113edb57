"""EMG processing as the original's ``processEmg`` (docs/preprocess.md), with MATLAB's ``filtfilt``.

Chain (time on axis 0, channels on axis 1):

1. sampling rate ``fs = n / (t_end - t_0)`` (the original divides the number of samples,
   not intervals, by the duration);
2. high-pass Butterworth (order 4, 40 Hz), zero phase (``filtfilt``);
3. subtract the mean (see ``demean`` below), rectify;
4. low-pass Butterworth (order 4, 10 Hz by default), zero phase;
5. negative values set to 0, subtract the minimum (``demean``), divide by each channel's
   maximum over the whole recording.

``filtfilt`` is MATLAB's: odd (point-reflected) extension of ``3 (max(len(a), len(b)) - 1)``
samples at each end and steady-state initial conditions scaled by the first sample of
each pass. scipy's default pads ``3 max(len(a), len(b))`` samples, which changes the
ends.

Across channels or per channel (``demean``): the original's ``processEmg`` receives
channels x frames and takes ``mean``/``min`` along the first dimension, i.e. **across
channels at each frame** (only the max normalization is per channel). ``demean="frame"``
(the default) does exactly that and reproduces the original's processed EMG of the tutorial
(tests/tools/preprocess/test_preprocess_emg.py, max |difference| 6e-9); ``"channel"``
subtracts each channel's own mean and minimum over time, the per-channel processing the
tutorial text describes (use it for single-channel recordings: across one channel the
frame mean is the sample itself).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import butter, lfilter, lfilter_zi

from nmsm.errors import InputError

#: ``"frame"``: the original's across-channel mean/min per frame; ``"channel"``: per channel
DEMEAN_MODES = ("frame", "channel")


def matlab_filtfilt(b: np.ndarray, a: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Zero-phase filtering of each column of ``x`` (n[, k]) exactly as MATLAB's ``filtfilt``."""
    b = np.atleast_1d(np.asarray(b, dtype=float))
    a = np.atleast_1d(np.asarray(a, dtype=float))
    x = np.asarray(x, dtype=float)
    n_filter = max(a.size, b.size)
    n_fact = 3 * (n_filter - 1)
    if x.shape[0] <= n_fact:
        raise InputError(
            f"{x.shape[0]} samples are too few to filter",
            expected=f"more than {n_fact} samples (3 x filter order)",
        )
    if a.size < n_filter:
        a = np.concatenate([a, np.zeros(n_filter - a.size)])
    if b.size < n_filter:
        b = np.concatenate([b, np.zeros(n_filter - b.size)])
    zi = lfilter_zi(b, a)
    shape = (-1,) + (1,) * (x.ndim - 1)
    head = 2.0 * x[0] - x[n_fact:0:-1]
    tail = 2.0 * x[-1] - x[-2 : -n_fact - 2 : -1]
    y = np.concatenate([head, x, tail], axis=0)
    y, _ = lfilter(b, a, y, axis=0, zi=zi.reshape(shape) * y[0])
    y = y[::-1]
    y, _ = lfilter(b, a, y, axis=0, zi=zi.reshape(shape) * y[0])
    return y[::-1][n_fact : n_fact + x.shape[0]]


#: raw EMG sampled below twice this rate (Hz) is suspected of times in milliseconds
MIN_EMG_RATE = 100.0


def sampling_rate(time: np.ndarray) -> float:
    """The original's ``length(t) / (t(end) - t(1))`` (Hz)."""
    t = np.asarray(time, dtype=float)
    if t.size < 2 or not t[-1] > t[0]:
        raise InputError("EMG time does not increase", element="time", expected="increasing sample times")
    return t.size / (t[-1] - t[0])


def process_emg(
    time: np.ndarray,
    data: np.ndarray,
    *,
    filter_order: int = 4,
    high_pass_cutoff: float = 40.0,
    low_pass_cutoff: float = 10.0,
    demean: str = "frame",
    labels: tuple[str, ...] | None = None,
) -> np.ndarray:
    """Processed EMG (n, channels) in [0, 1] from raw EMG ``data`` (n, channels) sampled at ``time`` (s).

    Cut-offs in Hz; ``demean``: ``"frame"`` (the original's across-channel mean and minimum
    at each frame) or ``"channel"`` (each channel's own over time). A channel that is
    constant after filtering (no signal) is an error naming it (``labels``, else its column
    number): its normalization would divide by zero.
    """
    x = np.asarray(data, dtype=float)
    if x.ndim != 2:
        raise InputError(f"EMG must be (frames, channels), got shape {x.shape}")
    if demean not in DEMEAN_MODES:
        raise InputError(f"unknown EMG demean mode '{demean}'", element="demean", expected=" or ".join(DEMEAN_MODES))
    per_frame = demean == "frame"
    if per_frame and x.shape[1] < 2:
        raise InputError("demeaning across channels needs several EMG channels", element="demean",
                         expected="demean='channel' for a single-channel recording")
    fs = sampling_rate(time)
    for name, cutoff in (("high-pass", high_pass_cutoff), ("low-pass", low_pass_cutoff)):
        if not 0 < cutoff < fs / 2:
            hint = f" (the EMG is sampled at {fs:g} Hz: are its times in milliseconds?)" if fs < 2 * MIN_EMG_RATE else ""
            raise InputError(f"{name} cut-off {cutoff} Hz{hint}", element=name,
                             expected=f"between 0 and {fs / 2:g} Hz (Nyquist)")
    raw = np.abs(x).max(axis=0)
    dead = np.flatnonzero(np.ptp(x, axis=0) <= 1e-12 * np.maximum(raw, 1e-300))
    if dead.size:  # the across-channel demean would give it the others' signal
        raise InputError(
            f"EMG channel(s) {', '.join(repr(labels[i]) if labels else f'column {int(i) + 1}' for i in dead)} "
            "carry no signal (the same value in every row: a dead electrode?)",
            element="EMG columns",
            expected="channels that vary over the trial (leave a dead channel out of the raw EMG file, or with "
                     "`nmsm preprocess --emg-channels`)",
        )
    b, a = butter(filter_order, 2.0 * high_pass_cutoff / fs, "high")
    x = matlab_filtfilt(b, a, x)
    x = x - (x.mean(axis=1, keepdims=True) if per_frame else x.mean(axis=0))
    x = np.abs(x)
    b, a = butter(filter_order, 2.0 * low_pass_cutoff / fs, "low")
    x = matlab_filtfilt(b, a, x)
    x[x < 0] = 0.0
    x = x - (x.min(axis=1, keepdims=True) if per_frame else x.min(axis=0))
    peak = x.max(axis=0)
    scale = np.abs(np.asarray(data, dtype=float)).max(axis=0)
    flat = np.flatnonzero(~(peak > 1e-9 * np.maximum(scale, 1e-300)))
    if flat.size:
        raise InputError(
            f"EMG channel(s) {', '.join(repr(labels[i]) if labels else f'column {int(i) + 1}' for i in flat)} "
            "carry no signal",
            element="EMG columns",
            expected="channels that vary over the trial",
        )
    return x / peak

"""Signal processing of coordinate trajectories as OpenSim's Inverse Dynamics tool does it.

1. :func:`pad`: ``Storage::pad(n)`` extends each column (time included) by ``n`` samples
   at both ends with a point reflection about the end samples (``2 x[0] - x[k]``), which
   keeps value and slope continuous. The ID tool pads by half the number of rows.
2. :func:`lowpass_iir`: a third-order Butterworth low-pass (bilinear transform with
   frequency pre-warping), run forward then backward for zero phase; the first three
   samples of each pass are copied unfiltered, as OpenSim does.
3. :func:`quintic_spline`: the natural quintic spline interpolating the samples (OpenSim's
   ``GCVSpline`` of degree 5 with zero error variance): value, first and second derivative.

Arrays: ``times`` ``(n,)`` in s, ``data`` ``(n, k)``.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import make_interp_spline

from nmsm.errors import InputError


def pad(values: np.ndarray, n_pad: int) -> np.ndarray:
    """Point-reflect ``n_pad`` samples onto both ends of each column of ``values`` (n[, k])."""
    x = np.asarray(values, dtype=float)
    if n_pad <= 0:
        return x.copy()
    n = x.shape[0]
    if n_pad > n - 1:
        raise InputError(f"cannot pad {n} samples by {n_pad}", expected=f"at most {n - 1} pad samples")
    head = 2.0 * x[0] - x[n_pad:0:-1]
    tail = 2.0 * x[-1] - x[-2:-n_pad - 2:-1]
    return np.concatenate([head, x, tail], axis=0)


def butterworth3_coefficients(sample_interval: float, cutoff_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """Numerator ``a`` (4,) and denominator ``b`` (4, ``b[0] = 1``) of the third-order
    Butterworth low-pass at ``cutoff_hz`` for samples ``sample_interval`` s apart.

    A cut-off at or above half the sampling frequency is lowered to 0.49 of it (OpenSim).
    """
    fs = 1.0 / sample_interval
    if cutoff_hz >= 0.5 * fs:
        cutoff_hz = 0.49 * fs
    wa = np.tan(np.pi * cutoff_hz * sample_interval)  # pre-warped analog cut-off
    # H(s) = 1 / ((s + 1)(s^2 + s + 1)) with s = (1 - z^-1) / (wa (1 + z^-1))
    first = np.array([1.0 + wa, wa - 1.0])
    second = np.array([1.0 + wa + wa * wa, 2.0 * wa * wa - 2.0, 1.0 - wa + wa * wa])
    denominator = np.convolve(first, second)
    numerator = wa**3 * np.array([1.0, 3.0, 3.0, 1.0])
    return numerator / denominator[0], denominator / denominator[0]


def _iir_pass(x: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    y = x.copy()
    for i in range(3, x.shape[0]):
        y[i] = (a[0] * x[i] + a[1] * x[i - 1] + a[2] * x[i - 2] + a[3] * x[i - 3]
                - b[1] * y[i - 1] - b[2] * y[i - 2] - b[3] * y[i - 3])
    return y


def lowpass_iir(data: np.ndarray, sample_interval: float, cutoff_hz: float) -> np.ndarray:
    """Zero-phase third-order Butterworth low-pass of each column of ``data`` (n[, k])."""
    x = np.asarray(data, dtype=float)
    if sample_interval <= 0:
        raise InputError("time samples are not increasing", expected="a positive sampling interval")
    a, b = butterworth3_coefficients(sample_interval, cutoff_hz)
    forward = _iir_pass(x, a, b)
    backward = _iir_pass(forward[::-1], a, b)
    return backward[::-1].copy()


def quintic_spline(times: np.ndarray, data: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Natural quintic interpolating spline of ``data`` (n, k) over ``times`` evaluated at
    ``at`` (m,): values, first and second derivatives, each ``(m, k)``."""
    t = np.asarray(times, dtype=float)
    if t.size < 6:
        raise InputError(f"{t.size} samples are too few for a quintic spline", expected="at least 6 samples")
    y = np.asarray(data, dtype=float)
    zero = np.zeros(y.shape[1:])
    natural = [(3, zero), (4, zero)]
    spline = make_interp_spline(t, y, k=5, bc_type=(natural, natural), axis=0)
    at = np.asarray(at, dtype=float)
    return spline(at), spline(at, 1), spline(at, 2)


def uniform_interval(times: np.ndarray, *, source: object = None) -> float:
    """The sampling interval of uniformly spaced ``times`` (s); InputError otherwise."""
    steps = np.diff(np.asarray(times, dtype=float))
    if steps.size == 0 or np.any(steps <= 0):
        raise InputError("time column is not increasing", file=source, element="time", expected="increasing times")
    dt = float(np.min(steps))
    mean = (times[-1] - times[0]) / (len(times) - 1)
    if mean - dt > 1e-9 * max(1.0, abs(mean)) and (np.max(steps) - dt) > 1e-6 * dt:
        raise InputError(f"low-pass filtering needs uniformly sampled data: {_step_changes(times, steps, dt)}",
                         file=source, element="time", expected="a constant time step")
    return dt


#: step changes named in the error of :func:`uniform_interval`
NAMED_STEP_CHANGES = 3


def _step_changes(times: np.ndarray, steps: np.ndarray, dt: float) -> str:
    """Where the time step of ``times`` changes: the first :data:`NAMED_STEP_CHANGES` times
    (s) with the step before and after, or the smallest and largest steps when it drifts."""
    changes = np.flatnonzero(np.abs(np.diff(steps)) > 1e-6 * dt)
    if changes.size == 0:
        small, large = int(np.argmin(steps)), int(np.argmax(steps))
        return (f"the time step drifts from {steps[small]:.6g} s (after t = {times[small]:.6g} s) to "
                f"{steps[large]:.6g} s (after t = {times[large]:.6g} s)")
    named = [f"t = {times[i + 1]:.6g} s ({steps[i]:.6g} s -> {steps[i + 1]:.6g} s)"
             for i in changes[:NAMED_STEP_CHANGES]]
    more = f" and {changes.size - NAMED_STEP_CHANGES} more" if changes.size > NAMED_STEP_CHANGES else ""
    return "the time step changes at " + ", ".join(named) + more

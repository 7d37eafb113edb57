"""EMG splines evaluated at delayed times, differentiable in the delay.

MTP's excitation is ``e(t_k) = S(t_k - delay)`` where ``S`` is MATLAB's not-a-knot cubic
``spline`` through (a subset of) the processed EMG samples and ``delay`` is a design
variable. MATLAB's ``ppval`` extrapolates with the first/last polynomial piece; so do we.

The spline is linear in its data, so :func:`spline_matrix` gives the coefficients as a
matrix times the data (needed when the data are symbolic, as in Synergy Extrapolation).
:func:`delayed_sampler` builds a CasADi SX function of ``(delay, coefficients)`` that picks
the piece holding each delayed sample among the few pieces the delay bounds allow, so its
first and second derivatives are exact.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from nmsm.errors import InputError


def spline_breaks(times: np.ndarray, stride: int = 1) -> np.ndarray:
    """Break points used for a spline through every ``stride``-th sample (s)."""
    t = np.asarray(times, dtype=float)
    return t[::stride]


def spline_coefficients(times: np.ndarray, values: np.ndarray, stride: int = 1) -> np.ndarray:
    """Not-a-knot cubic spline coefficients, MATLAB ``spline``/``pp.coefs`` order.

    ``times`` (n,) s, ``values`` (n, k) sampled at ``times``; returns (n_pieces, 4, k):
    piece i on ``[b_i, b_{i+1})`` is ``c0 x^3 + c1 x^2 + c2 x + c3`` with ``x = t - b_i``.
    """
    t = spline_breaks(times, stride)
    y = np.asarray(values, dtype=float)[::stride]
    if t.size < 2:
        raise InputError(f"an EMG spline needs at least 2 samples, got {t.size}")
    if not np.all(np.diff(t) > 0):
        raise InputError("EMG time column is not strictly increasing", element="time")
    if t.size == 2:  # MATLAB spline: straight line
        slope = (y[1] - y[0]) / (t[1] - t[0])
        c = np.zeros((1, 4) + y.shape[1:])
        c[0, 2], c[0, 3] = slope, y[0]
        return c
    if t.size == 3:  # MATLAB spline: the interpolating parabola, as 2 pieces
        sp = CubicSpline(t, y, bc_type="not-a-knot")
        return np.moveaxis(sp.c, 0, 1)
    sp = CubicSpline(t, y, bc_type="not-a-knot")
    return np.moveaxis(sp.c, 0, 1)  # (4, pieces, k) -> (pieces, 4, k)


def spline_matrix(times: np.ndarray, stride: int = 1) -> np.ndarray:
    """Linear map from the samples (n,) to flattened coefficients (n_pieces * 4,).

    Row ``4 * i + j`` gives coefficient ``c_j`` of piece ``i``; columns index all ``n``
    samples (skipped ones get zero columns).
    """
    t = np.asarray(times, dtype=float)
    n = t.size
    eye = np.eye(n)
    coefs = spline_coefficients(t, eye, stride)  # (pieces, 4, n)
    return coefs.reshape(-1, n)


def evaluate_pp(breaks: np.ndarray, coefs: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``ppval``: piecewise cubic at times ``t`` with end-piece extrapolation.

    ``coefs`` (n_pieces, 4, ...) as from :func:`spline_coefficients`; returns (len(t), ...).
    """
    b = np.asarray(breaks, dtype=float)
    t = np.asarray(t, dtype=float)
    idx = np.clip(np.searchsorted(b, t, side="right") - 1, 0, b.size - 2)
    x = (t - b[idx]).reshape((-1,) + (1,) * (coefs.ndim - 2))
    c = coefs[idx]
    return ((c[:, 0] * x + c[:, 1]) * x + c[:, 2]) * x + c[:, 3]


def _candidate_pieces(breaks: np.ndarray, t: float, max_delay: float) -> list[int]:
    """Pieces that ``t - d`` can fall into for ``d`` in ``[0, max_delay]``.

    Outside that range the nearest candidate's polynomial is used; the spline is C2, so at
    the range ends (``d`` on a bound) the result is exact up to rounding.
    """
    n_pieces = breaks.size - 1
    lo = np.searchsorted(breaks, t - max_delay, side="right") - 1
    hi = np.searchsorted(breaks, t, side="right") - 1
    lo = int(np.clip(lo, 0, n_pieces - 1))
    hi = int(np.clip(hi, 0, n_pieces - 1))
    return list(range(lo, hi + 1))


def delayed_sampler(breaks: np.ndarray, sample_times: np.ndarray, max_delay: float, name: str = "delayed_spline"):
    """CasADi ``Function(delay, coefs[4 * n_pieces]) -> samples[len(sample_times)]``.

    ``samples[k] = S(sample_times[k] - delay)`` for ``0 <= delay <= max_delay`` (s);
    ``coefs`` flattened as in :func:`spline_matrix`. Outside the breaks the end pieces
    extrapolate (MATLAB ``ppval``).
    """
    import casadi as cs

    b = np.asarray(breaks, dtype=float)
    n_pieces = b.size - 1
    d = cs.SX.sym("delay")
    c = cs.SX.sym("coefs", 4 * n_pieces)
    out = []
    for t in np.asarray(sample_times, dtype=float):
        tau = t - d
        cands = _candidate_pieces(b, float(t), float(max_delay))

        def piece(i: int) -> cs.SX:
            x = tau - b[i]
            return ((c[4 * i] * x + c[4 * i + 1]) * x + c[4 * i + 2]) * x + c[4 * i + 3]

        expr = piece(cands[-1])
        for i in reversed(cands[:-1]):
            expr = cs.if_else(tau < b[i + 1], piece(i), expr)
        out.append(expr)
    return cs.Function(name, [d, c], [cs.vertcat(*out)], ["delay", "coefs"], ["samples"])

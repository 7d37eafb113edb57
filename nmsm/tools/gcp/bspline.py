"""B-spline matrices of evenly sampled curves and the node count matching a cutoff frequency.

These reproduce the original pipeline's ``BSplineMatrices`` / ``calcBSplineDerivative`` /
``splFitWithCutoff`` of the original:

* :func:`bspline_matrices` - a clamped uniform B-spline of ``degree`` with ``nodes``
  control points evaluated on ``frames + 4`` samples ``interval`` apart (two padding
  samples at each end). The derivative matrices are central differences of the basis
  along time (one-sided at the ends, as MATLAB's ``gradient``); the padding rows are then
  removed. A curve ``q`` (frames,) is fitted by ``nodes = lstsq(N, q)`` and rebuilt as
  ``N @ nodes``, its rate as ``Np @ nodes``.
* :func:`derivative_matrix` - the linear map ``data -> Np @ lstsq(N, data)``: the
  smoothed time derivative used for the ground-reaction slope terms.
* :func:`nodes_for_cutoff` - the smallest node count (from 11 up) whose B-spline fit
  reproduces every curve's Fourier coefficients (linear trend plus ``round(fc T)``
  harmonics) within 1 % of the curve's largest harmonic coefficient.

Shapes: time along axis 0; ``N`` is ``(frames, nodes)``.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import BSpline

from nmsm.errors import InputError

#: first node count tried by :func:`nodes_for_cutoff`
FIRST_NODE_COUNT = 11
#: allowed error of the Fourier coefficients in :func:`nodes_for_cutoff` (percent)
ALLOWED_PERCENT_ERROR = 1.0


def bspline_matrices(degree: int, nodes: int, frames: int, interval: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(N, Np, Npp)``, each ``(frames, nodes)``: basis values, first and second time
    derivatives (1/s, 1/s^2) of a clamped uniform B-spline sampled every ``interval`` s."""
    if nodes < degree + 1:
        raise InputError(f"a degree-{degree} B-spline needs at least {degree + 1} nodes, got {nodes}",
                         expected=f"nodes >= {degree + 1}")
    if frames < 2:
        raise InputError(f"a B-spline fit needs at least 2 samples, got {frames}", expected="2 or more time frames")
    padded = frames + 4
    t_end = interval * (padded - 1)
    samples = np.linspace(0.0, t_end, padded)
    interior = np.arange(1, nodes - degree) * (t_end / (nodes - degree))
    knots = np.concatenate([np.zeros(degree + 1), interior, np.full(degree + 1, t_end)])
    basis = BSpline.design_matrix(samples, knots, degree).toarray()
    first = np.gradient(basis, interval, axis=0)
    second = np.gradient(first, interval, axis=0)
    keep = slice(2, padded - 2)
    return basis[keep], first[keep], second[keep]


def _interval(time: np.ndarray) -> float:
    time = np.asarray(time, dtype=float)
    if time.size < 2:
        raise InputError("a B-spline fit needs at least 2 time samples", expected="2 or more time frames")
    return float(time[1] - time[0])


def derivative_matrix(time: np.ndarray, degree: int, nodes: int) -> np.ndarray:
    """``(frames, frames)`` matrix ``D`` with ``D @ y`` the B-spline-smoothed rate of ``y``
    (``calcBSplineDerivative``); ``time`` (frames,) s, evenly spaced."""
    n, n_prime, _ = bspline_matrices(degree, nodes, len(time), _interval(time))
    return n_prime @ np.linalg.pinv(n)


def fit_nodes(basis: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Least-squares nodes ``(nodes, k)`` of curves ``values`` ``(frames, k)``."""
    solution, *_ = np.linalg.lstsq(basis, values, rcond=None)
    return solution


def _poly_fourier_design(time: np.ndarray, frequency: float, harmonics: int) -> np.ndarray:
    columns = [np.ones_like(time), time]
    w = 2.0 * np.pi * frequency
    for k in range(1, harmonics + 1):
        columns += [np.cos(k * w * time), np.sin(k * w * time)]
    return np.column_stack(columns)


def _sample_rate(time: np.ndarray) -> float:
    """The original's sampling-rate estimate (Hz): from the first ten intervals, rounded
    to 10 Hz (fewer samples: from the first interval)."""
    rate = round(1.0 / (time[10] - time[0])) * 10.0 if len(time) > 10 else float(round(1.0 / (time[1] - time[0])))
    if not rate > 0:  # round() halves to even: 5 Hz (0.5 -> 0) rounds to 0 too
        needed = ("more than 5 Hz (the rate is estimated from the first ten intervals and rounded to 10 Hz)"
                  if len(time) > 10 else "more than 0.5 Hz")
        raise InputError(f"the sampling rate of frames {time[1] - time[0]:.6g} s apart rounds to 0 Hz",
                         element="column 'time'", expected=f"times in seconds, sampled at {needed}")
    return rate


def nodes_for_cutoff(time: np.ndarray, curves: np.ndarray, cutoff_hz: float, degree: int = 4,
                     *, max_nodes: int | None = None) -> int:
    """Node count whose degree-``degree`` B-spline fit of ``curves`` ``(frames, k)`` keeps the
    Fourier content up to ``cutoff_hz`` (see module docstring)."""
    time = np.asarray(time, dtype=float)
    curves = np.asarray(curves, dtype=float).reshape(len(time), -1)
    frames = len(time)
    limit = max_nodes or frames
    rate = _sample_rate(time)
    even = np.arange(frames) / rate
    fundamental = 1.0 / even[-1]
    harmonics = int(round(cutoff_hz / fundamental))
    design = _poly_fourier_design(even, fundamental, harmonics)
    original = np.linalg.lstsq(design, curves, rcond=None)[0][2:]
    scale = np.maximum(np.abs(original).max(axis=0), 1e-8)
    for nodes in range(FIRST_NODE_COUNT, limit + 1):
        basis, _, _ = bspline_matrices(degree, nodes, frames, 1.0 / rate)
        fitted = basis @ fit_nodes(basis, curves)
        coefficients = np.linalg.lstsq(design, fitted, rcond=None)[0][2:]
        error = np.abs(coefficients - original) / scale * 100.0
        if error.max() <= ALLOWED_PERCENT_ERROR:
            return nodes
    return limit

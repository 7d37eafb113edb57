"""Reference signals (tracked data, initial controls, prescribed coordinates) as splines.

The original fits OpenSim ``GCVSplineSet(..., 5)`` with zero error variance: an
interpolating natural quintic spline. :class:`ReferenceSplines` fits one per column (scipy
``make_interp_spline``, degree 5, natural end conditions ``y''' = y'''' = 0``; lower
degrees when there are few samples) and evaluates values and time derivatives:

* numerically at given times (``values(times, order)``), used on the mesh when the final
  time is fixed or when references follow normalized time;
* symbolically at MX times (``symbolic(times, order)``) through CasADi B-spline functions,
  exactly differentiable w.r.t. the times (free final time with references in absolute
  time). Outside the data range the end polynomials are extended.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np
from scipy.interpolate import BSpline, make_interp_spline

from nmsm.errors import InputError


def _fit(time: np.ndarray, values: np.ndarray) -> BSpline:
    n = time.size
    k = 5 if n >= 6 else (3 if n >= 4 else 1)
    zero = np.zeros(values.shape[1:])
    if k == 5:
        bc = ([(3, zero), (4, zero)], [(3, zero), (4, zero)])
    elif k == 3:
        bc = ([(2, zero)], [(2, zero)])
    else:
        bc = None
    return make_interp_spline(time, values, k=k, bc_type=bc, axis=0)


@attrs.define
class ReferenceSplines:
    """Interpolating splines of the columns of a time table.

    ``time`` (n,) strictly increasing (s); ``data`` (n, k); ``labels`` (k,).
    """

    time: np.ndarray
    labels: tuple[str, ...]
    data: np.ndarray
    source: str | None = None
    _spline: BSpline = attrs.field(init=False, repr=False)
    _symbolic: dict[int, cs.Function] = attrs.field(init=False, factory=dict, repr=False)
    _symbolic_base: BSpline | None = attrs.field(init=False, default=None, repr=False)

    def __attrs_post_init__(self) -> None:
        self.time = np.asarray(self.time, dtype=float).ravel()
        self.data = np.asarray(self.data, dtype=float).reshape(self.time.size, -1)
        self.labels = tuple(self.labels)
        if self.data.shape[1] != len(self.labels):
            raise ValueError(f"{len(self.labels)} labels for {self.data.shape[1]} columns")
        if self.time.size < 2 or np.any(np.diff(self.time) <= 0):
            raise InputError(
                "time column must have at least 2 strictly increasing values",
                file=self.source,
                element="column 'time'",
            )
        self._spline = _fit(self.time, self.data)

    @classmethod
    def from_table(cls, table: Any, labels: Sequence[str] | None = None, *, scale: Sequence[float] | None = None,
                   shift_to_zero: bool = True) -> ReferenceSplines:
        """Splines of ``labels`` (default: all) of an :class:`nmsm.io.storage.Table`.

        ``scale`` multiplies columns (e.g. degrees -> radians); times start at 0 when
        ``shift_to_zero``.
        """
        labels = tuple(table.labels if labels is None else labels)
        data = table.columns(labels) if labels else np.zeros((table.n_rows, 0))
        if scale is not None:
            data = data * np.asarray(scale, dtype=float)[None, :]
        time = np.asarray(table.time, dtype=float)
        if shift_to_zero:
            time = time - time[0]
        src = str(table.source) if getattr(table, "source", None) else None
        return cls(time, labels, data, src)

    @property
    def duration(self) -> float:
        """Last time minus first (s)."""
        return float(self.time[-1] - self.time[0])

    def index(self, label: str) -> int:
        try:
            return self.labels.index(label)
        except ValueError:
            raise InputError(
                f"column '{label}' not found",
                file=self.source,
                element=f"column '{label}'",
                expected="one of " + ", ".join(self.labels),
            ) from None

    def has(self, label: str) -> bool:
        return label in self.labels

    def values(self, times: Any, order: int = 0, labels: Sequence[str] | None = None) -> np.ndarray:
        """(len(times), k) values or ``order``-th time derivatives (extrapolated outside)."""
        times = np.atleast_1d(np.asarray(times, dtype=float))
        out = self._spline(times, nu=order, extrapolate=True) if self.labels else np.zeros((times.size, 0))
        out = np.asarray(out).reshape(times.size, len(self.labels))
        if labels is None:
            return out
        return out[:, [self.index(label) for label in labels]]

    def _extended_spline(self) -> BSpline:
        """An interpolating spline through the data plus samples of the end polynomials on
        a range padded by one duration at each end (so symbolic evaluation extrapolates
        like :meth:`values`; inside the data range it differs from the fitted spline only
        by the end conditions' effect, ~1e-6 of the signal in tests)."""
        a, b = self.time[0], self.time[-1]
        pad = max(b - a, 1e-3)
        n_pad = max(8, self.time.size // 4)
        before = np.linspace(a - pad, a, n_pad, endpoint=False)
        after = np.linspace(b, b + pad, n_pad + 1)[1:]
        grid = np.concatenate([before, self.time, after])
        values = np.concatenate([self.values(before), self.data, self.values(after)])
        return _fit(grid, values)

    def _extended(self, order: int) -> cs.Function:
        """CasADi B-spline of the ``order``-th time derivative (padded range, see above)."""
        if order not in self._symbolic:
            if self._symbolic_base is None:
                self._symbolic_base = self._extended_spline()
            base = self._symbolic_base
            spline = base.derivative(order) if order else base
            k = len(self.labels)
            n_coeffs = len(spline.t) - spline.k - 1
            coeffs = np.asarray(spline.c).reshape(-1, k)[:n_coeffs]
            self._symbolic[order] = cs.Function.bspline(
                f"reference_d{order}", [list(spline.t)], coeffs.ravel().tolist(), [int(spline.k)], k
            )
        return self._symbolic[order]

    def symbolic(self, times: Any, order: int = 0, labels: Sequence[str] | None = None) -> cs.MX:
        """(n, k) MX values at MX ``times`` (n, 1); exact derivatives w.r.t. the times."""
        f = self._extended(order)
        times = cs.MX(times)
        cols = [f(times[i]).T for i in range(times.numel())]
        out = cs.vertcat(*cols) if cols else cs.MX(0, len(self.labels))
        if labels is None:
            return out
        return out[:, [self.index(label) for label in labels]]

"""OpenSim's one-variable functions, evaluated exactly as OpenSim evaluates them.

Each class is an attrs data class with two evaluation methods:

``f(x)``              generic: ``x`` is a float, a numpy array, or a CasADi ``SX``/``MX``
                      expression; only arithmetic and comparisons are used, so CasADi
                      differentiates the result exactly (derivatives of the interval
                      selection are zero).
``f.numeric(x, n)``   numpy: value (``n = 0``) or ``n``-th derivative at the points ``x``
                      (any shape; same shape returned).

Supported types (OpenSim XML tags): ``Constant``, ``LinearFunction``, ``SimmSpline``
(Forsythe-Malcolm-Moler cubic spline, linear extrapolation outside the knots),
``NaturalCubicSpline`` (natural end conditions, same evaluation rules), ``PiecewiseLinearFunction``
(linear extrapolation with the end segments' slopes), ``PolynomialFunction`` (coefficients
from the highest power down) and ``MultiplierFunction`` (``scale * f(x)``).
:func:`parse_function` turns an XML element into one of these and raises
:class:`~nmsm.errors.ModelError` for unsupported types or bad knots.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Union

import attrs
import numpy as np
from lxml import etree

from nmsm.errors import ModelError


def _floats(text: str | None) -> np.ndarray:
    return np.array([float(v) for v in (text or "").split()], dtype=float)


@attrs.frozen
class Constant:
    """``f(x) = value``."""

    value: float

    def __call__(self, x: Any) -> Any:
        return 0.0 * x + self.value

    def numeric(self, x: Any, order: int = 0) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        return np.full(x.shape, self.value if order == 0 else 0.0)


@attrs.frozen
class LinearFunction:
    """``f(x) = slope * x + intercept`` (OpenSim ``<coefficients>slope intercept``)."""

    slope: float
    intercept: float

    def __call__(self, x: Any) -> Any:
        return self.slope * x + self.intercept

    def numeric(self, x: Any, order: int = 0) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if order == 0:
            return self.slope * x + self.intercept
        return np.full(x.shape, self.slope if order == 1 else 0.0)


@attrs.frozen
class PolynomialFunction:
    """``f(x) = c[0] x^n + c[1] x^(n-1) + ... + c[n]`` (OpenSim/SimTK order)."""

    coefficients: tuple[float, ...]

    def __call__(self, x: Any) -> Any:
        value = 0.0 * x
        for c in self.coefficients:
            value = value * x + c
        return value

    def numeric(self, x: Any, order: int = 0) -> np.ndarray:
        poly = np.polynomial.Polynomial(self.coefficients[::-1]) if self.coefficients else np.polynomial.Polynomial([0.0])
        return poly.deriv(order)(np.asarray(x, dtype=float)) if order else poly(np.asarray(x, dtype=float))


@attrs.frozen(slots=False)
class PiecewiseCubic:
    """A piecewise cubic on knots ``x`` with linear extrapolation outside ``[x[0], x[-1]]``.

    On ``[x[i], x[i+1]]``: ``y[i] + b[i] t + c[i] t^2 + d[i] t^3`` with ``t = x - x[i]``.
    Below ``x[0]``: ``y[0] + b[0] (x - x[0])``; above ``x[-1]``: ``y[-1] + b[-1] (x - x[-1])``.
    Base of :class:`SimmSpline`, :class:`NaturalCubicSpline` and :class:`PiecewiseLinearFunction`.
    """

    x: np.ndarray = attrs.field(eq=False)
    y: np.ndarray = attrs.field(eq=False)
    b: np.ndarray = attrs.field(eq=False)
    c: np.ndarray = attrs.field(eq=False)
    d: np.ndarray = attrs.field(eq=False)
    #: piece used exactly at an interior knot ("right" or "left"; only derivatives of
    #: order above the continuity differ); the end knots always belong to the end pieces
    knot_side: str = "right"

    def _segments(self) -> tuple[np.ndarray, ...]:
        """Per-segment (base, y, b, c, d) including the two extrapolation segments."""
        n = len(self.x)
        base = np.concatenate([[self.x[0]], self.x[:-1], [self.x[-1]]])
        y = np.concatenate([[self.y[0]], self.y[:-1], [self.y[-1]]])
        b = np.concatenate([[self.b[0]], self.b[:-1], [self.b[-1]]])
        c = np.concatenate([[0.0], self.c[: n - 1], [0.0]])
        d = np.concatenate([[0.0], self.d[: n - 1], [0.0]])
        return base, y, b, c, d

    def __call__(self, x: Any) -> Any:
        if len(self.x) == 1:
            return 0.0 * x + self.y[0]
        if self._truncated_power_ok():
            return self._truncated_power(x)
        return self._selected_segment(x)

    def _truncated_power(self, x: Any) -> Any:
        """``s(x)`` as a cubic on the first piece plus third-derivative jumps
        ``(d[k] - d[k-1]) max(x - x[k], 0)^3`` at the interior knots (the pieces of a C2 cubic
        spline differ by exactly these terms), evaluated at ``x`` clamped to the knots, plus
        linear extrapolation beyond them. Few operations, exact derivatives."""
        lo, hi = float(self.x[0]), float(self.x[-1])
        inner = _fmin(_fmax(x, lo), hi)
        t = inner - lo
        value = self.y[0] + t * (self.b[0] + t * (self.c[0] + t * self.d[0]))
        for k in range(1, len(self.x) - 1):
            jump = float(self.d[k] - self.d[k - 1])
            if jump != 0.0:
                r = _fmax(inner - float(self.x[k]), 0.0)
                value = value + jump * (r * r * r)
        below = x - _fmax(x, lo)  # <= 0 below the knots, else 0
        above = x - _fmin(x, hi)  # >= 0 above the knots, else 0
        return value + float(self.b[0]) * below + float(self.b[-1]) * above

    def value_and_derivatives(self, x: Any) -> tuple[Any, Any, Any]:
        """``(s, s', s'')`` at ``x`` in closed form (same forms as ``__call__``)."""
        if len(self.x) == 1 or not self._truncated_power_ok():
            return _derivatives_by_ad(self, x)
        lo, hi = float(self.x[0]), float(self.x[-1])
        inner = _fmin(_fmax(x, lo), hi)
        t = inner - lo
        d1 = self.b[0] + t * (2.0 * self.c[0] + 3.0 * self.d[0] * t)
        d2 = 2.0 * self.c[0] + 6.0 * self.d[0] * t
        for k in range(1, len(self.x) - 1):
            jump = float(self.d[k] - self.d[k - 1])
            if jump != 0.0:
                r = _fmax(inner - float(self.x[k]), 0.0)
                d1 = d1 + 3.0 * jump * (r * r)
                d2 = d2 + 6.0 * jump * r
        inside = (x >= lo) * (x <= hi)
        return self(x), d1, d2 * inside

    def _truncated_power_ok(self) -> bool:
        """Whether the truncated-power form reproduces the piecewise form to 1e-13 (relative
        to the largest value) at the knots, midpoints and beyond the ends."""
        cached = getattr(self, "_tp_ok", None)
        if cached is not None:
            return cached
        if len(self.x) < 3:
            ok = False
        else:
            mids = 0.5 * (self.x[1:] + self.x[:-1])
            span = self.x[-1] - self.x[0]
            probe = np.concatenate([self.x, mids, [self.x[0] - 0.3 * span, self.x[-1] + 0.3 * span]])
            reference = self.numeric(probe)
            ours = np.array([float(self._truncated_power(v)) for v in probe])
            scale = max(1.0, float(np.abs(reference).max()))
            ok = bool(np.abs(ours - reference).max() <= 1e-13 * scale)
        object.__setattr__(self, "_tp_ok", ok)
        return ok

    def _selected_segment(self, x: Any) -> Any:
        """``s(x)`` with the piece chosen by exact 0/1 interval indicators (any knot count)."""
        base, y, b, c, d = self._segments()
        # indicator of each segment: exactly one is 1, the others exactly 0
        edges = [float(v) for v in self.x]
        last = len(edges) - 2
        indicators = [x < edges[0]]
        for k in range(len(edges) - 1):
            if self.knot_side == "right":
                lower = x >= edges[k]
                upper = (x <= edges[k + 1]) if k == last else (x < edges[k + 1])
            else:
                lower = (x >= edges[k]) if k == 0 else (x > edges[k])
                upper = x <= edges[k + 1]
            indicators.append(lower * upper)
        indicators.append(x > edges[-1])

        def pick(values: np.ndarray) -> Any:
            total = 0.0 * x
            for ind, v in zip(indicators, values):
                if v != 0.0:
                    total = total + ind * float(v)
            return total

        t = x - pick(base)
        return pick(y) + t * (pick(b) + t * (pick(c) + t * pick(d)))

    def numeric(self, x: Any, order: int = 0) -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if len(self.x) == 1:
            return np.full(x.shape, self.y[0] if order == 0 else 0.0)
        base, y, b, c, d = self._segments()
        n = len(self.x)
        k = np.searchsorted(self.x, x, side=self.knot_side)  # segment: 0 below, n above
        k = np.where(x == self.x[-1], n - 1, np.where(x == self.x[0], 1, k))
        t = x - base[k]
        if order == 0:
            return y[k] + t * (b[k] + t * (c[k] + t * d[k]))
        if order == 1:
            return b[k] + t * (2 * c[k] + 3 * t * d[k])
        if order == 2:
            return 2 * c[k] + 6 * t * d[k]
        if order == 3:
            return 6 * d[k]
        return np.zeros(x.shape)


def _derivatives_by_ad(function: Any, x: Any) -> tuple[Any, Any, Any]:
    import casadi as cs

    if not isinstance(x, (cs.SX, cs.MX)):
        return (function(x), function.numeric(x, 1), function.numeric(x, 2))
    s = cs.SX.sym("s")
    value = function(s)
    d1 = cs.gradient(value, s)
    d2 = cs.gradient(d1, s)
    return cs.Function("f", [s], [value, d1, d2])(x)


def value_and_derivatives(function: Any, x: Any) -> tuple[Any, Any, Any]:
    """``(f, f', f'')`` of any supported function at ``x`` (float, numpy or CasADi),
    in closed form for splines (cheaper derivative graphs than automatic differentiation)."""
    if isinstance(function, PiecewiseCubic):
        return function.value_and_derivatives(x)
    if isinstance(function, MultiplierFunction):
        v, d1, d2 = value_and_derivatives(function.function, x)
        return function.scale * v, function.scale * d1, function.scale * d2
    if isinstance(function, LinearFunction):
        return function(x), function.slope + 0.0 * x, 0.0 * x
    if isinstance(function, Constant):
        return function(x), 0.0 * x, 0.0 * x
    return _derivatives_by_ad(function, x)


def _fmax(a: Any, b: float) -> Any:
    if isinstance(a, (float, int, np.floating, np.ndarray)):
        return np.maximum(a, b)
    import casadi as cs

    return cs.fmax(a, b)


def _fmin(a: Any, b: float) -> Any:
    if isinstance(a, (float, int, np.floating, np.ndarray)):
        return np.minimum(a, b)
    import casadi as cs

    return cs.fmin(a, b)


def _check_knots(x: np.ndarray, y: np.ndarray, what: str, file: Any, element: str | None) -> None:
    if len(x) == 0 or len(x) != len(y):
        raise ModelError(
            f"{what} has {len(x)} x values and {len(y)} y values", file=file, element=element,
            expected="as many x as y values, at least one",
        )
    if not np.all(np.isfinite(x)) or not np.all(np.isfinite(y)):
        raise ModelError(f"{what} has non-finite knots", file=file, element=element, expected="finite numbers")
    if np.any(np.diff(x) <= 0):
        i = int(np.argmax(np.diff(x) <= 0))
        raise ModelError(
            f"{what} x values are not strictly increasing (x[{i}] = {x[i]:g}, x[{i + 1}] = {x[i + 1]:g})",
            file=file, element=element, expected="strictly increasing x",
        )


def fmm_spline_coefficients(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coefficients ``(b, c, d)`` of the Forsythe-Malcolm-Moler interpolating cubic spline.

    End conditions: the third derivative at each end matches the third divided difference
    of the four end points (for three points: zero third derivative at the ends; for two
    points: the straight line). Arrays of length ``len(x)``.
    """
    n = len(x)
    if n == 1:
        return np.zeros(1), np.zeros(1), np.zeros(1)
    h = np.diff(x)
    slope = np.diff(y) / h
    if n == 2:
        return np.full(2, slope[0]), np.zeros(2), np.zeros(2)
    # tridiagonal system for sigma = f''/6 at the knots, FMM end conditions in rows 0 and n-1
    lower = np.zeros(n)
    diag = np.zeros(n)
    upper = np.zeros(n)
    rhs = np.zeros(n)
    for i in range(1, n - 1):
        lower[i] = h[i - 1]
        diag[i] = 2.0 * (h[i - 1] + h[i])
        upper[i] = h[i]
        rhs[i] = slope[i] - slope[i - 1]
    diag[0], upper[0] = -h[0], h[0]
    lower[n - 1], diag[n - 1] = h[n - 2], -h[n - 2]
    if n > 3:
        second = np.diff(slope)  # second[i] = slope[i+1] - slope[i]
        rhs[0] = (second[1] / (x[3] - x[1]) - second[0] / (x[2] - x[0])) * h[0] ** 2 / (x[3] - x[0])
        rhs[n - 1] = -(
            (second[n - 3] / (x[n - 1] - x[n - 3]) - second[n - 4] / (x[n - 2] - x[n - 4]))
            * h[n - 2] ** 2 / (x[n - 1] - x[n - 4])
        )
    sigma = _solve_tridiagonal(lower, diag, upper, rhs)
    b = np.empty(n)
    c = np.empty(n)
    d = np.empty(n)
    b[: n - 1] = slope - h * (sigma[1:] + 2.0 * sigma[:-1])
    d[: n - 1] = (sigma[1:] - sigma[:-1]) / h
    c[: n - 1] = 3.0 * sigma[:-1]
    b[n - 1] = slope[-1] + h[-1] * (sigma[n - 2] + 2.0 * sigma[n - 1])
    c[n - 1] = 3.0 * sigma[n - 1]
    d[n - 1] = d[n - 2]
    return b, c, d


def natural_spline_coefficients(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coefficients ``(b, c, d)`` of the natural interpolating cubic spline (zero second
    derivative at both ends); arrays of length ``len(x)``, last entries continue the last piece."""
    n = len(x)
    if n == 1:
        return np.zeros(1), np.zeros(1), np.zeros(1)
    h = np.diff(x)
    slope = np.diff(y) / h
    if n == 2:
        return np.full(2, slope[0]), np.zeros(2), np.zeros(2)
    lower = np.zeros(n)
    diag = np.ones(n)
    upper = np.zeros(n)
    rhs = np.zeros(n)
    for i in range(1, n - 1):
        lower[i] = h[i - 1]
        diag[i] = 2.0 * (h[i - 1] + h[i])
        upper[i] = h[i]
        rhs[i] = 3.0 * (slope[i] - slope[i - 1])
    c = _solve_tridiagonal(lower, diag, upper, rhs)  # c = f''/2
    b = np.empty(n)
    d = np.empty(n)
    b[: n - 1] = slope - h * (2.0 * c[:-1] + c[1:]) / 3.0
    d[: n - 1] = (c[1:] - c[:-1]) / (3.0 * h)
    b[n - 1] = b[n - 2] + h[-1] * (2.0 * c[n - 2] + 3.0 * d[n - 2] * h[-1])
    d[n - 1] = 0.0
    return b, c, d


def _solve_tridiagonal(lower: np.ndarray, diag: np.ndarray, upper: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve a tridiagonal system (row i: lower[i] u[i-1] + diag[i] u[i] + upper[i] u[i+1] = rhs[i])."""
    n = len(diag)
    cp = np.zeros(n)
    dp = np.zeros(n)
    cp[0] = upper[0] / diag[0]
    dp[0] = rhs[0] / diag[0]
    for i in range(1, n):
        m = diag[i] - lower[i] * cp[i - 1]
        cp[i] = upper[i] / m if i < n - 1 else 0.0
        dp[i] = (rhs[i] - lower[i] * dp[i - 1]) / m
    u = np.zeros(n)
    u[-1] = dp[-1]
    for i in range(n - 2, -1, -1):
        u[i] = dp[i] - cp[i] * u[i + 1]
    return u


def SimmSpline(x: Any, y: Any, *, file: Any = None, element: str | None = None) -> PiecewiseCubic:
    """OpenSim's ``SimmSpline`` on knots ``(x, y)``; raises ModelError on bad knots."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    _check_knots(x, y, "SimmSpline", file, element)
    return PiecewiseCubic(x, y, *fmm_spline_coefficients(x, y))


def NaturalCubicSpline(x: Any, y: Any, *, file: Any = None, element: str | None = None) -> PiecewiseCubic:
    """OpenSim's ``NaturalCubicSpline`` on knots ``(x, y)``; raises ModelError on bad knots."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    _check_knots(x, y, "NaturalCubicSpline", file, element)
    return PiecewiseCubic(x, y, *natural_spline_coefficients(x, y))


def PiecewiseLinearFunction(x: Any, y: Any, *, file: Any = None, element: str | None = None) -> PiecewiseCubic:
    """OpenSim's ``PiecewiseLinearFunction``: linear interpolation, end slopes outside."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    _check_knots(x, y, "PiecewiseLinearFunction", file, element)
    if len(x) == 1:
        b = np.zeros(1)
    else:
        slope = np.diff(y) / np.diff(x)
        b = np.concatenate([slope, slope[-1:]])
    return PiecewiseCubic(x, y, b, np.zeros(len(x)), np.zeros(len(x)))


@attrs.frozen
class MultiplierFunction:
    """``f(x) = scale * function(x)``."""

    function: "Function"
    scale: float

    def __call__(self, x: Any) -> Any:
        return self.scale * self.function(x)

    def numeric(self, x: Any, order: int = 0) -> np.ndarray:
        return self.scale * self.function.numeric(x, order)


Function = Union[Constant, LinearFunction, PolynomialFunction, PiecewiseCubic, MultiplierFunction]

FUNCTION_TAGS = frozenset(
    {
        "Constant", "LinearFunction", "SimmSpline", "NaturalCubicSpline", "PiecewiseLinearFunction",
        "PolynomialFunction", "MultiplierFunction", "PiecewiseConstantFunction", "StepFunction",
        "Sine", "GCVSpline", "FunctionAdapter", "SigmoidFunction", "ExpressionBasedFunction",
    }
)


def _child_text(elem: etree._Element, tag: str) -> str | None:
    child = elem.find(tag)
    return None if child is None else child.text


def parse_function(elem: etree._Element, *, file: str | Path | None = None, owner: str = "") -> Function:
    """The function described by ``elem`` (an element whose tag is a function type).

    ``owner`` names the component using it (for error messages).
    """
    tag = elem.tag
    where = f"{owner} {tag}".strip() if owner else tag
    line = elem.sourceline
    try:
        if tag == "Constant":
            text = _child_text(elem, "value")
            return Constant(float(text) if text is not None and text.strip() else 0.0)
        if tag == "LinearFunction":
            coefs = _floats(_child_text(elem, "coefficients"))
            if len(coefs) == 0:
                coefs = np.array([1.0, 0.0])  # OpenSim's default
            if len(coefs) != 2:
                raise ModelError(f"has {len(coefs)} coefficients", file=file, line=line, element=where,
                                 expected="2 coefficients: slope intercept")
            return LinearFunction(float(coefs[0]), float(coefs[1]))
        if tag in ("SimmSpline", "NaturalCubicSpline", "PiecewiseLinearFunction"):
            x = _floats(_child_text(elem, "x"))
            y = _floats(_child_text(elem, "y"))
            maker = {"SimmSpline": SimmSpline, "NaturalCubicSpline": NaturalCubicSpline,
                     "PiecewiseLinearFunction": PiecewiseLinearFunction}[tag]
            try:
                return maker(x, y, file=file, element=where)
            except ModelError as exc:
                raise ModelError(exc.detail, file=file, line=line, element=where, expected=exc.expected) from None
        if tag == "PolynomialFunction":
            return PolynomialFunction(tuple(float(v) for v in _floats(_child_text(elem, "coefficients"))))
        if tag == "MultiplierFunction":
            holder = elem.find("function")
            inner = None
            if holder is not None:
                inner = next((c for c in holder if isinstance(c.tag, str)), None)
            if inner is None:
                raise ModelError("has no inner function", file=file, line=line, element=where,
                                 expected="<function> holding one function")
            scale_text = _child_text(elem, "scale")
            scale = float(scale_text) if scale_text is not None and scale_text.strip() else 1.0
            return MultiplierFunction(parse_function(inner, file=file, owner=owner), scale)
    except ValueError as exc:
        raise ModelError(f"unreadable number ({exc})", file=file, line=line, element=where) from None
    raise ModelError(
        f"function type '{tag}' is not supported", file=file, line=line, element=where,
        expected="Constant, LinearFunction, SimmSpline, NaturalCubicSpline, PiecewiseLinearFunction, "
        "PolynomialFunction or MultiplierFunction",
    )


def find_function(holder: etree._Element | None) -> etree._Element | None:
    """The first child of ``holder`` whose tag is a function type (or None)."""
    if holder is None:
        return None
    for child in holder:
        if isinstance(child.tag, str) and child.tag in FUNCTION_TAGS:
            return child
    return None

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


@attrs.frozen
class PiecewiseCubic:
    """A piecewise cubic on knots ``x`` with linear extrapolation outside ``[x[0], x[-1]]``.

    On ``[x[i], x[i+1])``: ``y[i] + b[i] t + c[i] t^2 + d[i] t^3`` with ``t = x - x[i]``.
    Below ``x[0]``: ``y[0] + b[0] (x - x[0])``; above ``x[-1]``: ``y[-1] + b[-1] (x - x[-1])``.
    Base of :class:`SimmSpline`, :class:`NaturalCubicSpline` and :class:`PiecewiseLinearFunction`.
    """

    x: np.ndarray = attrs.field(eq=False)
    y: np.ndarray = attrs.field(eq=False)
    b: np.ndarray = attrs.field(eq=False)
    c: np.ndarray = attrs.field(eq=False)
    d: np.ndarray = attrs.field(eq=False)

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
        base, y, b, c, d = self._segments()
        # indicator of each segment: exactly one is 1, the others exactly 0
        edges = list(self.x)
        indicators = [1.0 - (x >= edges[0])]
        for k in range(len(edges) - 1):
            indicators.append((x >= edges[k]) * (1.0 - (x >= edges[k + 1])))
        indicators.append(x >= edges[-1])

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
        k = np.searchsorted(self.x, x, side="right")  # 0: below, n: at/above last knot
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

"""The generic optimization problem every tool builds.

A tool declares design variables (bounds, scaling, initial values), static parameters,
cost residuals (usually from registered :class:`~nmsm.core.term.CostTerm` objects) and
constraints, all as CasADi MX expressions. The same problem is handed to a back end
registered by name (:mod:`nmsm.core.backends`), e.g.:

* ``least_squares`` - scipy ``least_squares`` with exact CasADi Jacobians (bounds only);
* ``ipopt``         - CasADi ``nlpsol`` with IPOPT, exact first and second derivatives.

Objective: ``sum_k weight_k * sum(residuals_k**2)``.

Variables are optimized in scaled form ``x = offset + scale * x_scaled``; the problem
hands unscaled expressions to the tool so terms never see the scaling.

A *lifted parameter* (:meth:`OptimizationProblem.lifted_parameter`) is a parameter that
stands for an expression of the design variables, affine in them, so that terms are built on
its symbol and a back end can differentiate through it cheaply; only the back end
``lifted_least_squares`` keeps it equal to its expression while solving, and the others
refuse such a problem.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.solution import ConstraintStatus, Solution
from nmsm.core.term import ConstraintTerm, CostTerm, SourceRef, Term, TermContext


def _as_array(value: Any, shape: tuple[int, int], what: str, name: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return np.full(shape, float(arr))
    try:
        return np.broadcast_to(arr.reshape(arr.shape if arr.ndim == 2 else (-1, 1)), shape).astype(float)
    except ValueError as exc:
        raise ValueError(f"variable '{name}': {what} has shape {arr.shape}, expected {shape}") from exc


@attrs.define
class Variable:
    """A block of design variables (shape ``(rows, cols)``; a vector is ``(n, 1)``)."""

    name: str
    shape: tuple[int, int]
    initial: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    scale: np.ndarray
    offset: np.ndarray
    scaled_symbol: cs.MX
    expression: cs.MX  # unscaled, for building terms
    start: int  # first index in the stacked scaled vector

    @property
    def size(self) -> int:
        return self.shape[0] * self.shape[1]

    def to_scaled(self, value: np.ndarray) -> np.ndarray:
        return np.ravel((np.asarray(value, dtype=float) - self.offset) / self.scale, order="F")

    def from_scaled(self, flat: np.ndarray) -> np.ndarray:
        block = np.reshape(flat, self.shape, order="F")
        return self.offset + self.scale * block


@attrs.define
class Parameter:
    """A static (non-optimized) input, e.g. experimental data a term needs symbolically."""

    name: str
    shape: tuple[int, int]
    value: np.ndarray
    symbol: cs.MX


@attrs.define
class CostEntry:
    name: str
    residuals: cs.MX
    weight: float
    source: SourceRef | None = None
    term: Term | None = None


@attrs.define
class ConstraintEntry:
    name: str
    expression: cs.MX
    lower: np.ndarray
    upper: np.ndarray
    source: SourceRef | None = None
    term: Term | None = None


class OptimizationProblem:
    """Design variables, parameters, cost residuals and constraints, solved by a back end."""

    def __init__(self, name: str = "problem") -> None:
        self.name = name
        self.variables: dict[str, Variable] = {}
        self.parameters: dict[str, Parameter] = {}
        self.costs: list[CostEntry] = []
        self.constraints: list[ConstraintEntry] = []
        #: lifted parameter name -> the expression of the design variables it stands for
        self.lifted: dict[str, cs.MX] = {}
        self._n = 0

    # ---- declaration -------------------------------------------------------------------
    def variable(
        self,
        name: str,
        initial: Any,
        lower: Any = -np.inf,
        upper: Any = np.inf,
        *,
        scale: Any = None,
        offset: Any = None,
        shape: tuple[int, int] | None = None,
    ) -> cs.MX:
        """Declare a design-variable block; returns its unscaled MX expression.

        ``initial``, ``lower``, ``upper``, ``scale``, ``offset`` broadcast to ``shape``
        (default: the shape of ``initial``; 1-D means a column). With ``scale=None`` the
        variable is scaled by its finite bound range (``offset`` = bound mid-point), else 1.
        """
        if name in self.variables or name in self.parameters:
            raise ValueError(f"'{name}' is declared twice in problem '{self.name}'")
        init = np.asarray(initial, dtype=float)
        if shape is None:
            shape = (init.size, 1) if init.ndim <= 1 else (init.shape[0], init.shape[1])
        init = _as_array(init, shape, "initial", name)
        lo = _as_array(lower, shape, "lower", name)
        hi = _as_array(upper, shape, "upper", name)
        if np.any(lo > hi):
            raise ValueError(f"variable '{name}': lower bound above upper bound")
        if scale is None:
            finite = np.isfinite(lo) & np.isfinite(hi) & (hi > lo)
            sc = np.ones(shape)
            sc[finite] = hi[finite] - lo[finite]
            if offset is None:
                off = np.zeros(shape)
                off[finite] = 0.5 * (hi[finite] + lo[finite])
            else:
                off = _as_array(offset, shape, "offset", name)
        else:
            sc = _as_array(scale, shape, "scale", name)
            off = np.zeros(shape) if offset is None else _as_array(offset, shape, "offset", name)
        if np.any(sc <= 0):
            raise ValueError(f"variable '{name}': scale must be > 0")
        sym = cs.MX.sym(name, shape[0], shape[1])
        expr = cs.DM(off) + cs.DM(sc) * sym
        var = Variable(name, shape, init, lo, hi, sc, off, sym, expr, self._n)
        self._n += var.size
        self.variables[name] = var
        return expr

    def parameter(self, name: str, value: Any) -> cs.MX:
        """Declare a static input; returns its MX symbol. Change it with :meth:`set_parameter`."""
        if name in self.variables or name in self.parameters:
            raise ValueError(f"'{name}' is declared twice in problem '{self.name}'")
        arr = np.asarray(value, dtype=float)
        shape = (arr.size, 1) if arr.ndim <= 1 else (arr.shape[0], arr.shape[1])
        sym = cs.MX.sym(name, shape[0], shape[1])
        self.parameters[name] = Parameter(name, shape, arr.reshape(shape), sym)
        return sym

    def lifted_parameter(self, name: str, expression: Any, value: Any) -> cs.MX:
        """Declare a parameter standing for ``expression``, an affine expression of the design
        variables; returns its MX symbol, to build terms on in place of the expression.

        ``value`` is the expression's value at the initial point (the parameter's value until a
        back end stores its value at the solution). Solved by ``lifted_least_squares``
        (:mod:`nmsm.core.backends.lifted_least_squares`).
        """
        expr = cs.MX(expression)
        symbol = self.parameter(name, value)
        if expr.shape != symbol.shape:
            del self.parameters[name]
            raise ValueError(f"lifted parameter '{name}': expression of shape {expr.shape}, value of shape "
                             f"{symbol.shape}")
        self.lifted[name] = expr
        return symbol

    def require_no_lifted_parameters(self, backend: str) -> None:
        """:class:`ValueError` when the problem has lifted parameters, which ``backend`` would
        hold at their stored values instead of following the design variables."""
        if self.lifted:
            raise ValueError(f"problem '{self.name}' has lifted parameters ({', '.join(list(self.lifted)[:5])}), "
                             f"which the {backend} back end cannot follow: use backend='lifted_least_squares', "
                             "or build the problem without lifting")

    def set_parameter(self, name: str, value: Any) -> None:
        p = self.parameters[name]
        p.value = np.asarray(value, dtype=float).reshape(p.shape)

    def set_initial(self, name: str, value: Any) -> None:
        v = self.variables[name]
        v.initial = _as_array(value, v.shape, "initial", name)

    def add_cost(self, name: str, residuals: Any, *, weight: float = 1.0,
                 source: SourceRef | None = None, term: Term | None = None) -> None:
        """Add ``weight * sum(residuals**2)`` to the objective."""
        self.costs.append(CostEntry(name, cs.vec(cs.MX(residuals)), float(weight), source, term))

    def add_constraint(self, name: str, expression: Any, lower: Any, upper: Any, *,
                       source: SourceRef | None = None, term: Term | None = None) -> None:
        """Add ``lower <= expression <= upper`` (bounds broadcast over the expression)."""
        expr = cs.vec(cs.MX(expression))
        n = expr.numel()
        lo = np.broadcast_to(np.asarray(lower, dtype=float).ravel(order="F"), (n,)).copy()
        hi = np.broadcast_to(np.asarray(upper, dtype=float).ravel(order="F"), (n,)).copy()
        self.constraints.append(ConstraintEntry(name, expr, lo, hi, source, term))

    def add_term(self, term: Term, ctx: TermContext, *, weight: float = 1.0) -> None:
        """Bind a registered term to ``ctx`` and add it as a cost or constraint."""
        term.bind(ctx)
        if isinstance(term, CostTerm):
            self.add_cost(term.label, term.residuals(ctx), weight=weight, source=term.source, term=term)
        elif isinstance(term, ConstraintTerm):
            expr, lo, hi = term.bounded(ctx)
            self.add_constraint(term.label, expr, lo, hi, source=term.source, term=term)
        else:
            raise TypeError(f"{term!r} is neither a CostTerm nor a ConstraintTerm")

    # ---- assembled pieces ---------------------------------------------------------------
    @property
    def n_variables(self) -> int:
        return self._n

    def scaled_vector(self) -> cs.MX:
        return cs.vertcat(*[cs.vec(v.scaled_symbol) for v in self.variables.values()]) if self.variables else cs.MX(0, 1)

    def parameter_vector(self) -> cs.MX:
        return cs.vertcat(*[cs.vec(p.symbol) for p in self.parameters.values()]) if self.parameters else cs.MX(0, 1)

    def parameter_values(self) -> np.ndarray:
        if not self.parameters:
            return np.zeros(0)
        return np.concatenate([np.ravel(p.value, order="F") for p in self.parameters.values()])

    def initial_scaled(self) -> np.ndarray:
        return np.concatenate([v.to_scaled(v.initial) for v in self.variables.values()]) if self.variables else np.zeros(0)

    def bounds_scaled(self) -> tuple[np.ndarray, np.ndarray]:
        lo = [v.to_scaled(v.lower) for v in self.variables.values()]
        hi = [v.to_scaled(v.upper) for v in self.variables.values()]
        return (np.concatenate(lo), np.concatenate(hi)) if lo else (np.zeros(0), np.zeros(0))

    def residual_vector(self) -> cs.MX:
        """All weighted residuals stacked: ``sqrt(weight_k) * residuals_k``."""
        parts = [np.sqrt(c.weight) * c.residuals for c in self.costs]
        return cs.vertcat(*parts) if parts else cs.MX(0, 1)

    def objective(self) -> cs.MX:
        total = cs.MX(0)
        for c in self.costs:
            total = total + c.weight * cs.sumsqr(c.residuals)
        return total

    def constraint_vector(self) -> tuple[cs.MX, np.ndarray, np.ndarray]:
        if not self.constraints:
            return cs.MX(0, 1), np.zeros(0), np.zeros(0)
        g = cs.vertcat(*[c.expression for c in self.constraints])
        return g, np.concatenate([c.lower for c in self.constraints]), np.concatenate([c.upper for c in self.constraints])

    def unpack(self, x_scaled: np.ndarray) -> dict[str, np.ndarray]:
        out = {}
        for v in self.variables.values():
            block = v.from_scaled(np.asarray(x_scaled)[v.start : v.start + v.size])
            out[v.name] = block
        return out

    def function(self, expressions: Sequence[Any] | Any, name: str = "f") -> cs.Function:
        """CasADi Function of (scaled x, parameters) returning ``expressions``."""
        outs = list(expressions) if isinstance(expressions, (list, tuple)) else [expressions]
        return cs.Function(name, [self.scaled_vector(), self.parameter_vector()], [cs.MX(o) for o in outs])

    def evaluate(self, expression: Any, x_scaled: np.ndarray) -> np.ndarray:
        """Numeric value of ``expression`` at a scaled point (``Solution.x_scaled``)."""
        return np.array(self.function(expression).call([x_scaled, self.parameter_values()])[0].full())

    def term_costs(self, x_scaled: np.ndarray) -> dict[str, float]:
        """Objective contribution of each cost entry at a scaled point."""
        if not self.costs:
            return {}
        f = self.function([c.weight * cs.sumsqr(c.residuals) for c in self.costs], "term_costs")
        values = f.call([x_scaled, self.parameter_values()])
        out: dict[str, float] = {}
        for c, v in zip(self.costs, values):
            key = c.name
            k = 2
            while key in out:
                key = f"{c.name}#{k}"
                k += 1
            out[key] = float(v)
        return out

    def constraint_report(self, x_scaled: np.ndarray, tol: float = 1e-6) -> tuple[ConstraintStatus, ...]:
        if not self.constraints:
            return ()
        f = self.function([c.expression for c in self.constraints], "constraints")
        values = f.call([x_scaled, self.parameter_values()])
        report = []
        for c, v in zip(self.constraints, values):
            g = np.asarray(v.full()).ravel()
            viol = np.maximum(c.lower - g, 0) + np.maximum(g - c.upper, 0)
            span = np.maximum(np.abs(c.upper - c.lower), 1.0)
            active = (np.abs(g - c.lower) <= tol * span) | (np.abs(g - c.upper) <= tol * span)
            report.append(ConstraintStatus(c.name, g.size, float(viol.max(initial=0.0)), int(active.sum()), c.source))
        return tuple(report)

    # ---- solving ------------------------------------------------------------------------
    def solve(self, backend: str = "ipopt", **options: Any) -> Solution:
        """Solve with the back end registered as ``backend`` (``ipopt``, ``least_squares``, ...:
        ``nmsm plugins --kind backend``); options go to the back end."""
        from nmsm.core.backends.base import get_backend

        return get_backend(backend).solve(self, **options)

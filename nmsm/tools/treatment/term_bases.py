"""Base classes of Treatment Optimization terms (TO, VO, DO).

Subclass one of these, set ``type`` (the settings name) and ``tools``, declare the term's
XML elements as attrs fields, check names in ``bind`` and compute the raw quantity from the
:class:`~nmsm.tools.treatment.context.TreatmentContext` (see its docstring for every
quantity, with units and shapes):

``ContinuousCost``     ``quantity(ctx)`` -> (K, 1) on the collocation points; the objective
                       gets ``integral_0^1 ((g - c)/e)^2 ds`` over normalized time ``s``
                       (a time average; times ``t_f`` when ``normalize_by_final_time`` is
                       false), restricted to ``time_ranges`` if given.
``DiscreteCost``       ``quantity(ctx)`` -> scalar; the objective gets ``((v - c)/e)^2``.
``PathConstraint``     ``value(ctx)`` -> (K, 1); ``min_error <= g(t_k) <= max_error`` at the
                       collocation points (within ``time_ranges`` if given).
``TerminalConstraint`` ``value(ctx)`` -> scalar (use ``ctx.initial`` / ``ctx.final``);
                       ``min_error <= v <= max_error``.

Example (a complete continuous cost term)::

    @attrs.frozen(kw_only=True)
    class GeneralizedSpeedMinimization(ContinuousCost):
        \"\"\"Minimizes one coordinate's speed (rad/s or m/s).\"\"\"

        type: ClassVar[str] = "generalized_speed_minimization"
        tools: ClassVar[frozenset[str]] = frozenset({"TO", "VO", "DO"})
        coordinate: str

        def bind(self, ctx):
            ctx.require_coordinate(self, self.coordinate)

        def quantity(self, ctx):
            return ctx.speed(self.coordinate)

The objective is the mean over continuous terms of their integrals plus the mean over
discrete terms (``normalize_cost_by_term_type``: averaged per type first); the tool sets
each term's weight accordingly.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import ConstraintTerm, CostTerm, TermValueError

TREATMENT_TOOLS = frozenset({"TO", "VO", "DO"})


def _ranges(instance: Any, attribute: attrs.Attribute, value: tuple[float, ...] | None) -> None:
    expected = "pairs 'start end' of normalized time with 0 <= start < end <= 1"
    if value is None:
        return
    if len(value) % 2 or not value:
        raise TermValueError(f"'{attribute.name}' needs pairs 'start end' in normalized time [0, 1], got {value}",
                             field=attribute.name, expected=expected)
    for a, b in zip(value[::2], value[1::2]):
        if not (0.0 <= a < b <= 1.0):
            raise TermValueError(f"'{attribute.name}': each range must satisfy 0 <= start < end <= 1, got {a} {b}",
                                 field=attribute.name, expected=expected)


@attrs.frozen(kw_only=True)
class ContinuousCost(CostTerm):
    """A cost integrated over the movement (see module docstring)."""

    discrete: ClassVar[bool] = False
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS

    #: normalized-time ranges "a b [c d ...]" where the integrand counts (elsewhere 0)
    time_ranges: tuple[float, ...] | None = attrs.field(default=None, validator=_ranges)
    #: true: time average (integral over normalized time); false: integral over time (s)
    normalize_by_final_time: bool = True


@attrs.frozen(kw_only=True)
class DiscreteCost(CostTerm):
    """A cost evaluated once per solution (scalar quantity)."""

    discrete: ClassVar[bool] = True
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS


@attrs.frozen(kw_only=True)
class PathConstraint(ConstraintTerm):
    """A constraint enforced at every collocation point."""

    terminal: ClassVar[bool] = False
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS

    time_ranges: tuple[float, ...] | None = attrs.field(default=None, validator=_ranges)


@attrs.frozen(kw_only=True)
class TerminalConstraint(ConstraintTerm):
    """A constraint on values at the start and/or end of the movement (scalar)."""

    terminal: ClassVar[bool] = True
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS


def require_axis(term: Any, axis: str | None) -> int:
    """Index 0/1/2 of ``term.axis`` ('x', 'y', 'z'), or an InputError naming the term."""
    if axis not in ("x", "y", "z"):
        raise term.error(f"axis '{axis}' is not one of x, y, z", element="<axes>", expected="x, y and/or z")
    return "xyz".index(axis)

"""Terminal constraints (docs/terms.md): values at the movement's start (t0) and end (t_f).

For each family - ``generalized_coordinate``, ``generalized_speed``, ``marker_position``,
``marker_velocity``, ``body_orientation``, ``external_force``, ``external_moment`` - five types:

``<family>_periodicity``        value(t_f) - value(t0)
``initial_<family>_deviation``  modeled(t0) - tracked(t0)
``initial_<family>_value``      modeled(t0)
``final_<family>_deviation``    modeled(t_f) - tracked(t_f)
``final_<family>_value``        modeled(t_f)

plus ``root_segment_residual_load_periodicity`` (τ_ID(t_f) - τ_ID(t0) of a load; uses the
real end accelerations, unlike the original, see docs/treatment.md). Each is bounded by
``[min_error, max_error]``. Periodicity of generalized coordinates is only accepted for
state coordinates (prescribed ones follow the data). Units: those of the family.

Half gait cycles: ``periodicity`` with ``<pair_coordinate>`` compares ``value(t_f)`` of the
term's coordinate with ``value(t0)`` of the paired one (left/right mapping), as Moco's
periodicity goal.
"""

from __future__ import annotations

import sys
from typing import Any, ClassVar

import attrs

from nmsm.core.signals import SIGNALS
from nmsm.core.ocp import TerminalConstraint

VARIANTS = ("periodicity", "initial_deviation", "initial_value", "final_deviation", "final_value")


@attrs.frozen(kw_only=True)
class _Terminal(TerminalConstraint):
    family: ClassVar[str] = ""
    variant: ClassVar[str] = ""

    def bind(self, ctx: Any) -> None:
        SIGNALS[self.family].bind(ctx, self)

    def _at(self, view: Any, term: Any = None) -> Any:
        return SIGNALS[self.family].modeled(view, term or self)

    def value(self, ctx: Any) -> Any:
        s = SIGNALS[self.family]
        if self.variant == "periodicity":
            return self._at(ctx.final) - self._start_value(ctx)
        view = ctx.initial if self.variant.startswith("initial") else ctx.final
        value = s.modeled(view, self)
        if self.variant.endswith("deviation"):
            value = value - s.tracked(view, self)
        return value

    def _start_value(self, ctx: Any) -> Any:
        return self._at(ctx.initial)


@attrs.frozen(kw_only=True)
class _CoordinateTerminal(_Terminal):
    coordinate: str
    #: periodicity only: compare with this coordinate at t0 (left/right mapping of half cycles)
    pair_coordinate: str | None = None

    def bind(self, ctx: Any) -> None:
        super().bind(ctx)
        if self.variant == "periodicity" and self.family == "generalized_coordinate":
            ctx.require_state_coordinate(self, self.coordinate)
        if self.pair_coordinate is not None:
            if self.variant != "periodicity":
                raise self.error("<pair_coordinate> applies to periodicity terms only", element="<pair_coordinate>")
            ctx.require_coordinate(self, self.pair_coordinate, element="<pair_coordinate>")

    def _start_value(self, ctx: Any) -> Any:
        if self.pair_coordinate is None:
            return self._at(ctx.initial)
        return self._at(ctx.initial, attrs.evolve(self, coordinate=self.pair_coordinate, pair_coordinate=None))


@attrs.frozen(kw_only=True)
class _MarkerTerminal(_Terminal):
    marker: str
    axis: str | None = None


@attrs.frozen(kw_only=True)
class _BodyTerminal(_Terminal):
    body: str
    axis: str | None = None
    sequence: str | None = None


@attrs.frozen(kw_only=True)
class _ForceTerminal(_Terminal):
    force: str


@attrs.frozen(kw_only=True)
class _MomentTerminal(_Terminal):
    moment: str


@attrs.frozen(kw_only=True)
class RootSegmentResidualLoadPeriodicity(_Terminal):
    """τ_ID(t_f) - τ_ID(t0) of a load (N·m or N)."""

    type: ClassVar[str] = "root_segment_residual_load_periodicity"
    family: ClassVar[str] = "root_segment_residual_load"
    variant: ClassVar[str] = "periodicity"
    load: str


_BASES = {
    "generalized_coordinate": _CoordinateTerminal,
    "generalized_speed": _CoordinateTerminal,
    "marker_position": _MarkerTerminal,
    "marker_velocity": _MarkerTerminal,
    "body_orientation": _BodyTerminal,
    "external_force": _ForceTerminal,
    "external_moment": _MomentTerminal,
}


def _type_name(family: str, variant: str) -> str:
    if variant == "periodicity":
        return f"{family}_periodicity"
    when, kind = variant.split("_")
    return f"{when}_{family}_{kind}"


def _class_name(type_name: str) -> str:
    return "".join(part.capitalize() for part in type_name.split("_"))


def _make(family: str, variant: str) -> type:
    type_name = _type_name(family, variant)
    unit = SIGNALS[family].unit
    doc = {
        "periodicity": f"value(t_f) - value(t0) of {family.replace('_', ' ')} ({unit}).",
        "initial_deviation": f"modeled - tracked {family.replace('_', ' ')} at t0 ({unit}).",
        "initial_value": f"modeled {family.replace('_', ' ')} at t0 ({unit}).",
        "final_deviation": f"modeled - tracked {family.replace('_', ' ')} at t_f ({unit}).",
        "final_value": f"modeled {family.replace('_', ' ')} at t_f ({unit}).",
    }[variant]
    namespace = {
        "__doc__": doc,
        "__module__": __name__,
        "__qualname__": _class_name(type_name),
        "__annotations__": {"type": "ClassVar[str]", "family": "ClassVar[str]", "variant": "ClassVar[str]"},
        "type": type_name,
        "family": family,
        "variant": variant,
    }
    cls = type(_class_name(type_name), (_BASES[family],), namespace)
    return attrs.frozen(kw_only=True)(cls)


_module = sys.modules[__name__]
for _family in _BASES:
    for _variant in VARIANTS:
        _cls = _make(_family, _variant)
        setattr(_module, _cls.__name__, _cls)
del _module, _family, _variant, _cls

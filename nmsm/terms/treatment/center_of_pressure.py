"""Centre-of-pressure tracking (docs/terms.md; contact models, TO/DO).

``center_of_pressure_tracking``   CoP - CoP_exp of one foot on one floor axis (``x`` or ``z``, m).
The foot is named by its ``<hindfoot_body>`` (``<hindfoot_body_list>``): every contact model
acting on that body first (an ``.osimx`` elastic-foundation surface, or the smooth spheres of
that body) contributes to the foot's force and moment. Modeled CoP about the surface's
reference point P on the floor: ``x = P_x + M_z/F̂_y``, ``z = P_z - M_x/F̂_y``,
``F̂_y = F_y + sign(F_y)`` (sign(0) = 1); experimental CoP the same about the electrical centre
(tracked GRF columns). ``<time_ranges>`` is required (the CoP means nothing in swing).
Options: ``use_relative_error`` + ``min_reference_value`` (default 1 m): the error is divided
by ``max(|CoP_exp|, min_reference_value)``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import ContinuousCost


def require_floor_axis(term: Any) -> int:
    """Index 0 or 2 of the term's ``axis`` (the CoP lies on the floor: x or z)."""
    if term.axis not in ("x", "z"):
        raise term.error(f"axis '{term.axis}' is not a floor axis of the centre of pressure", element="<axes>",
                         expected="x and/or z")
    return "xyz".index(term.axis)


def require_time_ranges(term: Any) -> None:
    if not term.time_ranges:
        raise term.error("the centre of pressure needs <time_ranges> (the stance phases, normalized time)",
                         element="<time_ranges>", expected="pairs 'start end' in [0, 1]")


@attrs.frozen(kw_only=True)
class CenterOfPressureTracking(ContinuousCost):
    """Tracks a foot's centre of pressure on one floor axis: CoP - CoP_exp (m)."""

    type: ClassVar[str] = "center_of_pressure_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    #: the leg of nmsm.testing.check_term: its foot stands on the belt the whole movement
    check_example: ClassVar[Mapping[str, str]] = {"time_ranges": "0 1", "axis": "x"}
    hindfoot_body: str
    axis: str | None = None
    use_relative_error: bool = False
    min_reference_value: float = 1.0

    def bind(self, ctx: Any) -> None:
        require_floor_axis(self)
        require_time_ranges(self)
        ctx.require_hindfoot_body(self, self.hindfoot_body, tracked=True)

    def quantity(self, ctx: Any) -> Any:
        i = "xyz".index(self.axis)
        reference = cs.MX(ctx.tracked_center_of_pressure(self.hindfoot_body)[:, i])
        error = ctx.center_of_pressure(self.hindfoot_body)[:, i] - reference
        if self.use_relative_error:
            error = error / cs.fmax(cs.fabs(reference), self.min_reference_value)
        return error


@attrs.frozen(kw_only=True)
class CenterOfPresssureTracking(CenterOfPressureTracking):
    """``center_of_presssure_tracking``: the misspelt name of the original's ``Cost Terms.pdf``,
    accepted as an alias of ``center_of_pressure_tracking`` (same term)."""

    type: ClassVar[str] = "center_of_presssure_tracking"

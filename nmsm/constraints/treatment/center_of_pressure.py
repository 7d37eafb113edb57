"""Centre-of-pressure path constraints (docs/terms.md; contact models, TO and DO, not VO).

``center_of_pressure_deviation``  CoP - CoP_exp of one foot on one floor axis (m)
``center_of_pressure_value``      CoP (m)
The foot is named by ``<hindfoot_body>`` (``<hindfoot_body_list>``), the axis by ``<axes>``
(``x`` and/or ``z``); ``<time_ranges>`` (stance, normalized time) is required. The CoP is that
of :mod:`nmsm.terms.treatment.center_of_pressure`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.terms.treatment.center_of_pressure import require_floor_axis, require_time_ranges
from nmsm.core.ocp import PathConstraint


@attrs.frozen(kw_only=True)
class _CenterOfPressurePath(PathConstraint):
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    #: the leg of nmsm.testing.check_term: its foot stands on the belt the whole movement
    check_example: ClassVar[Mapping[str, str]] = {"time_ranges": "0 1", "axis": "x"}
    deviation: ClassVar[bool] = False
    hindfoot_body: str
    axis: str | None = None

    def bind(self, ctx: Any) -> None:
        require_floor_axis(self)
        require_time_ranges(self)
        ctx.require_hindfoot_body(self, self.hindfoot_body, tracked=self.deviation)

    def value(self, ctx: Any) -> Any:
        i = "xyz".index(self.axis)
        value = ctx.center_of_pressure(self.hindfoot_body)[:, i]
        if self.deviation:
            value = value - cs.MX(ctx.tracked_center_of_pressure(self.hindfoot_body)[:, i])
        return value


@attrs.frozen(kw_only=True)
class CenterOfPressureDeviation(_CenterOfPressurePath):
    """CoP - CoP_exp of a foot on one floor axis (m)."""

    type: ClassVar[str] = "center_of_pressure_deviation"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class CenterOfPressureValue(_CenterOfPressurePath):
    """CoP of a foot on one floor axis (m)."""

    type: ClassVar[str] = "center_of_pressure_value"

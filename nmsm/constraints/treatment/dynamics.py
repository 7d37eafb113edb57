"""Physics constraints of the implicit formulation (docs/terms.md), path constraints.

``kinetic_consistency``        τ_ID(load) - (muscle moments + torque controls on the load's
                               coordinate), N·m or N: the controllers must produce the loads the
                               motion needs
``root_segment_residual_load`` τ_ID(load): residual loads of unactuated (root) coordinates,
                               optionally only within ``time_ranges``
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.ocp import PathConstraint


@attrs.frozen(kw_only=True)
class KineticConsistency(PathConstraint):
    """τ_ID - controller loads on one coordinate (N·m or N)."""

    type: ClassVar[str] = "kinetic_consistency"
    load: str

    def bind(self, ctx: Any) -> None:
        ctx.require_load(self, self.load)
        coordinate = ctx.load_coordinate(self.load)
        if not ctx.is_actuated(coordinate):
            raise self.error(
                f"load '{self.load}': coordinate '{coordinate}' is actuated by no controller (neither a torque "
                "control nor a muscle of the synergy/muscle controllers spans it)",
                element="<load_list>", expected="loads of controlled coordinates")

    def value(self, ctx: Any) -> Any:
        return ctx.inverse_dynamics_load(self.load) - ctx.controller_load(self.load)


@attrs.frozen(kw_only=True)
class RootSegmentResidualLoad(PathConstraint):
    """Residual inverse-dynamics load τ_ID of a coordinate (N·m or N)."""

    type: ClassVar[str] = "root_segment_residual_load"
    load: str

    def bind(self, ctx: Any) -> None:
        ctx.require_load(self, self.load)

    def value(self, ctx: Any) -> Any:
        return ctx.inverse_dynamics_load(self.load)

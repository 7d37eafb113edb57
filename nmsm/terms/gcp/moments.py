"""Ground reaction moment tracking: ``ground_reaction_moment`` and its slope."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.gcp._base import FootCostTerm


@attrs.frozen(kw_only=True)
class GroundReactionMoment(FootCostTerm):
    """Modeled minus experimental ground reaction moments (N m) about the midfoot-superior
    marker projected on the floor, 3 axes, every frame."""

    type: ClassVar[str] = "ground_reaction_moment"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.moment_errors(foot)


@attrs.frozen(kw_only=True)
class GroundReactionMomentSlope(FootCostTerm):
    """Modeled minus experimental rates of the ground reaction moments (N m/s)."""

    type: ClassVar[str] = "ground_reaction_moment_slope"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.moment_slope_errors(foot)

"""Ground reaction force tracking: ``vertical_grf``, ``horizontal_grf`` and their slopes."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.gcp._base import FootCostTerm

_VERTICAL = (1,)
_HORIZONTAL = (0, 2)


@attrs.frozen(kw_only=True)
class VerticalGrf(FootCostTerm):
    """Modeled minus experimental vertical ground reaction force (N), every frame."""

    type: ClassVar[str] = "vertical_grf"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.force_errors(foot, _VERTICAL)


@attrs.frozen(kw_only=True)
class VerticalGrfSlope(FootCostTerm):
    """Modeled minus experimental rate of the vertical ground reaction force (N/s)."""

    type: ClassVar[str] = "vertical_grf_slope"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.force_slope_errors(foot, _VERTICAL)


@attrs.frozen(kw_only=True)
class HorizontalGrf(FootCostTerm):
    """Modeled minus experimental anterior (x) and lateral (z) ground reaction forces (N)."""

    type: ClassVar[str] = "horizontal_grf"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.force_errors(foot, _HORIZONTAL)


@attrs.frozen(kw_only=True)
class HorizontalGrfSlope(FootCostTerm):
    """Modeled minus experimental rates of the horizontal ground reaction forces (N/s)."""

    type: ClassVar[str] = "horizontal_grf_slope"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.force_slope_errors(foot, _HORIZONTAL)

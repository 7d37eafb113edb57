"""Foot-marker tracking: ``marker_position`` and ``marker_slope``."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.gcp._base import FootCostTerm


@attrs.frozen(kw_only=True)
class MarkerPosition(FootCostTerm):
    """Modeled minus experimental positions (m) of the five foot markers, 3 axes, every frame."""

    type: ClassVar[str] = "marker_position"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.marker_errors(foot)


@attrs.frozen(kw_only=True)
class MarkerSlope(FootCostTerm):
    """Modeled minus experimental velocities (m/s) of the five foot markers (experimental:
    the markers moved by the B-spline fit of the experimental foot kinematics)."""

    type: ClassVar[str] = "marker_slope"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.marker_velocity_errors(foot)

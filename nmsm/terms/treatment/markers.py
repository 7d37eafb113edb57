"""Marker and body-orientation costs (docs/terms.md). ``<axes>`` splits into one term per axis.

``marker_position_tracking``      p_exp - p on one axis (m), tracked = marker on the tracked IK
``marker_velocity_tracking``      ṗ_exp - ṗ (m/s)
``body_orientation_tracking``     θ - θ_exp about one axis (rad), body-fixed angles in
                                  ``sequence`` (default xyz)
``body_orientation_minimization`` θ (about error_center)
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.signals import SIGNALS
from nmsm.core.ocp import ContinuousCost


@attrs.frozen(kw_only=True)
class _MarkerCost(ContinuousCost):
    marker: str
    axis: str | None = None

    def bind(self, ctx: Any) -> None:
        SIGNALS["marker_position"].bind(ctx, self)


@attrs.frozen(kw_only=True)
class MarkerPositionTracking(_MarkerCost):
    """Tracks a marker coordinate: p_exp - p (m)."""

    type: ClassVar[str] = "marker_position_tracking"

    def quantity(self, ctx: Any) -> Any:
        s = SIGNALS["marker_position"]
        return s.tracked(ctx, self) - s.modeled(ctx, self)


@attrs.frozen(kw_only=True)
class MarkerVelocityTracking(_MarkerCost):
    """Tracks a marker velocity component: ṗ_exp - ṗ (m/s)."""

    type: ClassVar[str] = "marker_velocity_tracking"

    def quantity(self, ctx: Any) -> Any:
        s = SIGNALS["marker_velocity"]
        return s.tracked(ctx, self) - s.modeled(ctx, self)


@attrs.frozen(kw_only=True)
class _BodyCost(ContinuousCost):
    body: str
    axis: str | None = None
    sequence: str | None = None

    def bind(self, ctx: Any) -> None:
        SIGNALS["body_orientation"].bind(ctx, self)


@attrs.frozen(kw_only=True)
class BodyOrientationTracking(_BodyCost):
    """Tracks a body angle: θ - θ_exp (rad)."""

    type: ClassVar[str] = "body_orientation_tracking"

    def quantity(self, ctx: Any) -> Any:
        s = SIGNALS["body_orientation"]
        return s.modeled(ctx, self) - s.tracked(ctx, self)


@attrs.frozen(kw_only=True)
class BodyOrientationMinimization(_BodyCost):
    """Minimizes a body angle θ about error_center (rad)."""

    type: ClassVar[str] = "body_orientation_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})

    def quantity(self, ctx: Any) -> Any:
        return SIGNALS["body_orientation"].modeled(ctx, self)

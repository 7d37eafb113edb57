"""Generalized coordinate, speed and acceleration costs (docs/terms.md).

``generalized_coordinate_tracking``   q_exp - q      (rad or m)
``generalized_speed_tracking``        q̇_exp - q̇      (rad/s or m/s)
``generalized_speed_minimization``    q̇              (error_center c subtracted by the base)
``generalized_acceleration_tracking`` q̈_exp - q̈      (rad/s² or m/s²)
``generalized_acceleration_minimization`` q̈
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.ocp import ContinuousCost


@attrs.frozen(kw_only=True)
class _CoordinateCost(ContinuousCost):
    """A continuous cost on one model coordinate (``<coordinate_list>`` splits into terms)."""

    coordinate: str

    def bind(self, ctx: Any) -> None:
        ctx.require_coordinate(self, self.coordinate)


@attrs.frozen(kw_only=True)
class GeneralizedCoordinateTracking(_CoordinateCost):
    """Tracks a coordinate: q_exp - q (rad or m)."""

    type: ClassVar[str] = "generalized_coordinate_tracking"

    def quantity(self, ctx: Any) -> Any:
        return ctx.tracked_coordinate(self.coordinate) - ctx.coordinate(self.coordinate)


@attrs.frozen(kw_only=True)
class GeneralizedSpeedTracking(_CoordinateCost):
    """Tracks a coordinate's speed: q̇_exp - q̇ (rad/s or m/s)."""

    type: ClassVar[str] = "generalized_speed_tracking"

    def quantity(self, ctx: Any) -> Any:
        return ctx.tracked_speed(self.coordinate) - ctx.speed(self.coordinate)


@attrs.frozen(kw_only=True)
class GeneralizedSpeedMinimization(_CoordinateCost):
    """Minimizes a coordinate's speed q̇ (rad/s or m/s) about ``error_center``."""

    type: ClassVar[str] = "generalized_speed_minimization"

    def quantity(self, ctx: Any) -> Any:
        return ctx.speed(self.coordinate)


@attrs.frozen(kw_only=True)
class GeneralizedAccelerationTracking(_CoordinateCost):
    """Tracks a coordinate's acceleration: q̈_exp - q̈ (rad/s² or m/s²)."""

    type: ClassVar[str] = "generalized_acceleration_tracking"

    def quantity(self, ctx: Any) -> Any:
        return ctx.tracked_acceleration(self.coordinate) - ctx.acceleration(self.coordinate)


@attrs.frozen(kw_only=True)
class GeneralizedAccelerationMinimization(_CoordinateCost):
    """Minimizes a coordinate's acceleration q̈ (rad/s² or m/s²)."""

    type: ClassVar[str] = "generalized_acceleration_minimization"

    def quantity(self, ctx: Any) -> Any:
        return ctx.acceleration(self.coordinate)

"""Path constraints on kinematic signals, controls and muscles (catalog §1.4).

``<family>_deviation`` = modeled - tracked, ``<family>_value`` = modeled, at every collocation
point, bounded by ``[min_error, max_error]``. Families: ``generalized_coordinate``,
``generalized_speed``, ``generalized_acceleration`` (rad|m, /s, /s²), ``marker_position``,
``marker_velocity`` (m, m/s; one ``axis``), ``body_orientation`` (rad; ``axis``, ``sequence``),
``external_force`` / ``external_moment`` (ground reaction columns of the contact models, N, N·m).
Also ``controller_deviation`` (u - scale·u_init) / ``controller_value`` (u),
``muscle_activation_deviation`` (a - scale·a_exp) / ``muscle_activation_value`` (a), and
``limit_normalized_fiber_length`` (l̃ of a muscle, DO).
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.signals import SIGNALS
from nmsm.core.ocp import PathConstraint


@attrs.frozen(kw_only=True)
class _SignalPath(PathConstraint):
    family: ClassVar[str] = ""
    deviation: ClassVar[bool] = False

    def bind(self, ctx: Any) -> None:
        SIGNALS[self.family].bind(ctx, self)

    def value(self, ctx: Any) -> Any:
        s = SIGNALS[self.family]
        value = s.modeled(ctx, self)
        return value - s.tracked(ctx, self) if self.deviation else value


@attrs.frozen(kw_only=True)
class _CoordinatePath(_SignalPath):
    coordinate: str


@attrs.frozen(kw_only=True)
class _MarkerPath(_SignalPath):
    marker: str
    axis: str | None = None


@attrs.frozen(kw_only=True)
class _BodyPath(_SignalPath):
    body: str
    axis: str | None = None
    sequence: str | None = None


@attrs.frozen(kw_only=True)
class GeneralizedCoordinateDeviation(_CoordinatePath):
    """q - q_exp (rad or m)."""

    type: ClassVar[str] = "generalized_coordinate_deviation"
    family: ClassVar[str] = "generalized_coordinate"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class GeneralizedCoordinateValue(_CoordinatePath):
    """q (rad or m)."""

    type: ClassVar[str] = "generalized_coordinate_value"
    family: ClassVar[str] = "generalized_coordinate"


@attrs.frozen(kw_only=True)
class GeneralizedSpeedDeviation(_CoordinatePath):
    """q̇ - q̇_exp (rad/s or m/s)."""

    type: ClassVar[str] = "generalized_speed_deviation"
    family: ClassVar[str] = "generalized_speed"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class GeneralizedSpeedValue(_CoordinatePath):
    """q̇ (rad/s or m/s)."""

    type: ClassVar[str] = "generalized_speed_value"
    family: ClassVar[str] = "generalized_speed"


@attrs.frozen(kw_only=True)
class GeneralizedAccelerationDeviation(_CoordinatePath):
    """q̈ - q̈_exp (rad/s² or m/s²)."""

    type: ClassVar[str] = "generalized_acceleration_deviation"
    family: ClassVar[str] = "generalized_acceleration"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class GeneralizedAccelerationValue(_CoordinatePath):
    """q̈ (rad/s² or m/s²)."""

    type: ClassVar[str] = "generalized_acceleration_value"
    family: ClassVar[str] = "generalized_acceleration"


@attrs.frozen(kw_only=True)
class MarkerPositionDeviation(_MarkerPath):
    """p - p_exp on one axis (m)."""

    type: ClassVar[str] = "marker_position_deviation"
    family: ClassVar[str] = "marker_position"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class MarkerPositionValue(_MarkerPath):
    """p on one axis (m)."""

    type: ClassVar[str] = "marker_position_value"
    family: ClassVar[str] = "marker_position"


@attrs.frozen(kw_only=True)
class MarkerVelocityDeviation(_MarkerPath):
    """ṗ - ṗ_exp on one axis (m/s)."""

    type: ClassVar[str] = "marker_velocity_deviation"
    family: ClassVar[str] = "marker_velocity"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class MarkerVelocityValue(_MarkerPath):
    """ṗ on one axis (m/s)."""

    type: ClassVar[str] = "marker_velocity_value"
    family: ClassVar[str] = "marker_velocity"


@attrs.frozen(kw_only=True)
class BodyOrientationDeviation(_BodyPath):
    """θ - θ_exp about one axis (rad)."""

    type: ClassVar[str] = "body_orientation_deviation"
    family: ClassVar[str] = "body_orientation"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class BodyOrientationValue(_BodyPath):
    """θ about one axis (rad)."""

    type: ClassVar[str] = "body_orientation_value"
    family: ClassVar[str] = "body_orientation"


@attrs.frozen(kw_only=True)
class _ForcePath(_SignalPath):
    force: str


@attrs.frozen(kw_only=True)
class _MomentPath(_SignalPath):
    moment: str


@attrs.frozen(kw_only=True)
class ExternalForceDeviation(_ForcePath):
    """F - F_exp of a ground reaction force column (N)."""

    type: ClassVar[str] = "external_force_deviation"
    family: ClassVar[str] = "external_force"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class ExternalForceValue(_ForcePath):
    """F of a ground reaction force column (N)."""

    type: ClassVar[str] = "external_force_value"
    family: ClassVar[str] = "external_force"


@attrs.frozen(kw_only=True)
class ExternalMomentDeviation(_MomentPath):
    """M - M_exp of a ground reaction moment column (N·m)."""

    type: ClassVar[str] = "external_moment_deviation"
    family: ClassVar[str] = "external_moment"
    deviation: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class ExternalMomentValue(_MomentPath):
    """M of a ground reaction moment column (N·m)."""

    type: ClassVar[str] = "external_moment_value"
    family: ClassVar[str] = "external_moment"


@attrs.frozen(kw_only=True)
class ControllerDeviation(PathConstraint):
    """u - scale·u_init (control units)."""

    type: ClassVar[str] = "controller_deviation"
    controller: str
    scale_factor: float = 1.0

    def bind(self, ctx: Any) -> None:
        ctx.require_control(self, self.controller)

    def value(self, ctx: Any) -> Any:
        return ctx.control(self.controller) - self.scale_factor * ctx.initial_control(self.controller)


@attrs.frozen(kw_only=True)
class ControllerValue(PathConstraint):
    """u (control units)."""

    type: ClassVar[str] = "controller_value"
    controller: str

    def bind(self, ctx: Any) -> None:
        ctx.require_control(self, self.controller)

    def value(self, ctx: Any) -> Any:
        return ctx.control(self.controller)


@attrs.frozen(kw_only=True)
class MuscleActivationDeviation(PathConstraint):
    """a - scale·a_exp (0..1)."""

    type: ClassVar[str] = "muscle_activation_deviation"
    muscle: str
    scale_factor: float = 1.0

    def bind(self, ctx: Any) -> None:
        ctx.require_tracked_activation(self, self.muscle)

    def value(self, ctx: Any) -> Any:
        return ctx.muscle_activation(self.muscle) - self.scale_factor * ctx.tracked_muscle_activation(self.muscle)


@attrs.frozen(kw_only=True)
class MuscleActivationValue(PathConstraint):
    """a (0..1)."""

    type: ClassVar[str] = "muscle_activation_value"
    muscle: str

    def bind(self, ctx: Any) -> None:
        ctx.require_muscle(self, self.muscle)

    def value(self, ctx: Any) -> Any:
        return ctx.muscle_activation(self.muscle)


@attrs.frozen(kw_only=True)
class LimitNormalizedFiberLength(PathConstraint):
    """Normalized fiber length l̃ of a muscle (dimensionless)."""

    type: ClassVar[str] = "limit_normalized_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    muscle: str

    def bind(self, ctx: Any) -> None:
        ctx.require_muscle(self, self.muscle)

    def value(self, ctx: Any) -> Any:
        return ctx.normalized_fiber_length(self.muscle)

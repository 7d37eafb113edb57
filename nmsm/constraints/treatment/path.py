"""Path constraints on kinematic signals, controls and muscles (docs/terms.md).

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
class _ForcePath(_SignalPath):
    force: str


@attrs.frozen(kw_only=True)
class _MomentPath(_SignalPath):
    moment: str


#: One row per signal family: (family, class-name stem, base with the family's fields,
#: docstring of ``<family>_value``, docstring of ``<family>_deviation``).
_SIGNAL_PATHS: tuple[tuple[str, str, type, str, str], ...] = (
    ("generalized_coordinate", "GeneralizedCoordinate", _CoordinatePath, "q (rad or m).", "q - q_exp (rad or m)."),
    ("generalized_speed", "GeneralizedSpeed", _CoordinatePath, "q̇ (rad/s or m/s).", "q̇ - q̇_exp (rad/s or m/s)."),
    ("generalized_acceleration", "GeneralizedAcceleration", _CoordinatePath, "q̈ (rad/s² or m/s²).",
     "q̈ - q̈_exp (rad/s² or m/s²)."),
    ("marker_position", "MarkerPosition", _MarkerPath, "p on one axis (m).", "p - p_exp on one axis (m)."),
    ("marker_velocity", "MarkerVelocity", _MarkerPath, "ṗ on one axis (m/s).", "ṗ - ṗ_exp on one axis (m/s)."),
    ("body_orientation", "BodyOrientation", _BodyPath, "θ about one axis (rad).", "θ - θ_exp about one axis (rad)."),
    ("external_force", "ExternalForce", _ForcePath, "F of a ground reaction force column (N).",
     "F - F_exp of a ground reaction force column (N)."),
    ("external_moment", "ExternalMoment", _MomentPath, "M of a ground reaction moment column (N·m).",
     "M - M_exp of a ground reaction moment column (N·m)."),
)


def _signal_path_class(family: str, stem: str, base: type, doc: str, deviation: bool) -> type:
    """The registered class ``<stem>Deviation`` (``<family>_deviation``) or ``<stem>Value``."""
    suffix = "Deviation" if deviation else "Value"
    namespace = {"__doc__": doc, "__module__": __name__, "__qualname__": stem + suffix,
                 "type": f"{family}_{suffix.lower()}", "family": family, "deviation": deviation}
    return attrs.frozen(kw_only=True)(type(stem + suffix, (base,), namespace))


for _family, _stem, _base, _value_doc, _deviation_doc in _SIGNAL_PATHS:
    for _deviation, _doc in ((True, _deviation_doc), (False, _value_doc)):
        _cls = _signal_path_class(_family, _stem, _base, _doc, _deviation)
        globals()[_cls.__name__] = _cls
del _family, _stem, _base, _value_doc, _deviation_doc, _deviation, _doc, _cls


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

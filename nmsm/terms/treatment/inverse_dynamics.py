"""Inverse-dynamics load costs (docs/terms.md). ``load`` is an ID label
(``<coordinate>_moment`` / ``<coordinate>_force``; a coordinate name is accepted too).

``inverse_dynamics_load_tracking``       scale·τ_exp - τ_ID            (N·m or N)
``inverse_dynamics_load_minimization``   τ_ID
``inverse_dynamics_slope_tracking``      Δτ_ID/Δt - Δτ_exp/Δt          (N·m/s; forward differences
                                         between collocation points, last row 0)
``inverse_dynamics_shape_tracking``      τ_exp - k·τ_ID, k = (τ_ID·τ_exp)/(τ_ID·τ_ID) (DO;
                                         the original's version cannot run, this is the
                                         intended math)
``joint_energy_generation_goal``         P = τ_ID·q̇ of the load's coordinate (W); the integrand
                                         is (max(P - c, 0)/e)² (DO, the intended math)
``joint_energy_absorption_goal``         same with -P
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import ContinuousCost


@attrs.frozen(kw_only=True)
class _LoadCost(ContinuousCost):
    load: str

    def bind(self, ctx: Any) -> None:
        ctx.require_load(self, self.load)


@attrs.frozen(kw_only=True)
class _TrackedLoadCost(_LoadCost):
    scale_factor: float = 1.0

    def bind(self, ctx: Any) -> None:
        ctx.require_tracked_load(self, self.load)


@attrs.frozen(kw_only=True)
class InverseDynamicsLoadTracking(_TrackedLoadCost):
    """Tracks an inverse-dynamics load: scale·τ_exp - τ_ID (N·m or N)."""

    type: ClassVar[str] = "inverse_dynamics_load_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})

    def quantity(self, ctx: Any) -> Any:
        return self.scale_factor * ctx.tracked_load(self.load) - ctx.inverse_dynamics_load(self.load)


@attrs.frozen(kw_only=True)
class InverseDynamicsLoadMinimization(_LoadCost):
    """Minimizes an inverse-dynamics load τ_ID (N·m or N)."""

    type: ClassVar[str] = "inverse_dynamics_load_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.inverse_dynamics_load(self.load)


def forward_difference(values: Any, times: Any) -> Any:
    """(n, 1) forward differences ``(v[k+1] - v[k]) / (t[k+1] - t[k])``, last row 0."""
    n = values.shape[0]
    if n < 2:
        return cs.MX(n, 1)
    slope = (values[1:, 0] - values[:-1, 0]) / (times[1:, 0] - times[:-1, 0])
    return cs.vertcat(slope, cs.MX(1, 1))


@attrs.frozen(kw_only=True)
class InverseDynamicsSlopeTracking(_TrackedLoadCost):
    """Tracks the slope of an ID load: Δτ_ID/Δt - Δτ_exp/Δt (N·m/s or N/s)."""

    type: ClassVar[str] = "inverse_dynamics_slope_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})

    def quantity(self, ctx: Any) -> Any:
        t = ctx.time()
        return forward_difference(ctx.inverse_dynamics_load(self.load), t) - forward_difference(
            cs.MX(ctx.tracked_load(self.load)), t)


@attrs.frozen(kw_only=True)
class InverseDynamicsShapeTracking(_TrackedLoadCost):
    """Tracks the shape of an ID load: τ_exp - k·τ_ID with the least-squares scale k."""

    type: ClassVar[str] = "inverse_dynamics_shape_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})

    def quantity(self, ctx: Any) -> Any:
        model = ctx.inverse_dynamics_load(self.load)
        exp = cs.MX(ctx.tracked_load(self.load))
        k = cs.dot(model, exp) / (cs.dot(model, model) + 1e-12)
        return exp - k * model


@attrs.frozen(kw_only=True)
class _JointPower(_LoadCost):
    sign: ClassVar[float] = 1.0

    def quantity(self, ctx: Any) -> Any:
        coordinate = ctx.load_coordinate(self.load)
        power = self.sign * ctx.inverse_dynamics_load(self.load) * ctx.speed(coordinate)
        return self.error_center + cs.fmax(power - self.error_center, 0)


@attrs.frozen(kw_only=True)
class JointEnergyGenerationGoal(_JointPower):
    """Penalizes joint power generation τ_ID·q̇ above error_center (W)."""

    type: ClassVar[str] = "joint_energy_generation_goal"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})


@attrs.frozen(kw_only=True)
class JointEnergyAbsorptionGoal(_JointPower):
    """Penalizes joint power absorption -τ_ID·q̇ above error_center (W)."""

    type: ClassVar[str] = "joint_energy_absorption_goal"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    sign: ClassVar[float] = -1.0

"""Metabolic cost goals (DO, discrete; docs/terms.md; the smoothed Bhargava model of
:mod:`nmsm.tools.treatment.metabolics`).

``Ė(t)`` (W) is the whole-body metabolic rate of :meth:`TreatmentContext.metabolic_rate`
(every muscle of the synergy / individual-muscle controllers plus the basal rate
1.2 W/kg × body mass). With ``P̄ = (1/t_f) ∫₀^{t_f} Ė dt = ∫₀¹ Ė ds`` the mean metabolic power
(W) and ``v`` the mean forward centre-of-mass speed (m/s, ``relative_walking_speed_goal``)
plus the mean belt speed of the contact surfaces (m/s, 0 without a treadmill):

``absolute_metabolic_cost_per_time``      r = P̄                       (W)
``absolute_metabolic_cost_per_distance``  r = P̄ / v                   (J/m)
``relative_metabolic_cost_per_time``      r = P̄ / P̄₀                   (-)
``relative_metabolic_cost_per_distance``  r = (P̄ / v) / (P̄₀ / v₀)     (-)

``P̄₀``, ``v₀`` are evaluated once at the initial guess. The objective gets ``((r - c)/e)²``.
Departure (units): the original divides its normalized-time integral of Ė (already the mean
power) once more by ``t_f``; here the per-time cost is the mean power itself (W) and the
per-distance cost energy per distance (J/m). Relative costs agree with the original when the
final time is fixed. The original also computes Ė only when a ``relative_*`` type is enabled;
here every type triggers it.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.treatment.walking_speed import mean_forward_speed
from nmsm.core.ocp import DiscreteCost


def mean_metabolic_power(ctx: Any) -> Any:
    """``∫₀¹ Ė ds`` (W), an MX scalar."""
    return ctx.integrate(ctx.metabolic_rate())


def metabolic_cost_per_distance(ctx: Any) -> Any:
    """Mean metabolic power over travelled speed (J/m), an MX scalar."""
    return mean_metabolic_power(ctx) / (mean_forward_speed(ctx) + ctx.belt_speed())


@attrs.frozen(kw_only=True)
class _MetabolicGoal(DiscreteCost):
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    per_distance: ClassVar[bool] = False
    relative: ClassVar[bool] = False

    def bind(self, ctx: Any) -> None:
        ctx.require_metabolic_model(self)
        if self.per_distance:
            ctx.require_whole_body(self)

    def _absolute(self, ctx: Any) -> Any:
        return metabolic_cost_per_distance(ctx) if self.per_distance else mean_metabolic_power(ctx)

    def quantity(self, ctx: Any) -> Any:
        value = self._absolute(ctx)
        if not self.relative:
            return value
        baseline = float(ctx.initial_guess_value(value).ravel()[0])
        if not baseline > 0:
            raise self.error(f"the metabolic cost at the initial guess is {baseline:g}, cannot be a reference",
                             element="<type>")
        return value / baseline


@attrs.frozen(kw_only=True)
class AbsoluteMetabolicCostPerTime(_MetabolicGoal):
    """Drives the mean metabolic power P̄ (W) to ``error_center``."""

    type: ClassVar[str] = "absolute_metabolic_cost_per_time"


@attrs.frozen(kw_only=True)
class AbsoluteMetabolicCostPerDistance(_MetabolicGoal):
    """Drives the metabolic energy per distance P̄ / v (J/m) to ``error_center``."""

    type: ClassVar[str] = "absolute_metabolic_cost_per_distance"
    per_distance: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class RelativeMetabolicCostPerTime(_MetabolicGoal):
    """Drives the mean metabolic power relative to the initial guess's, P̄ / P̄₀, to ``error_center``."""

    type: ClassVar[str] = "relative_metabolic_cost_per_time"
    relative: ClassVar[bool] = True


@attrs.frozen(kw_only=True)
class RelativeMetabolicCostPerDistance(_MetabolicGoal):
    """Drives the energy per distance relative to the initial guess's to ``error_center``."""

    type: ClassVar[str] = "relative_metabolic_cost_per_distance"
    per_distance: ClassVar[bool] = True
    relative: ClassVar[bool] = True

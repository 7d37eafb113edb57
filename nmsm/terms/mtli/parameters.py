"""MTLI parameter terms: fiber/tendon length variables and the muscle-stress scale."""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm


def _change(ctx, variable, initial):
    """Scale factors (scale mode) or absolute change ``l - l0`` in m (absolute mode)."""
    if ctx.absolute_lengths:
        return cs.reshape(cs.MX(variable), 1, -1) - cs.DM(initial.reshape(1, -1))
    return cs.reshape(cs.MX(variable), 1, -1)


@attrs.frozen(kw_only=True)
class MtliOptimalMuscleFiberLength(CostTerm):
    """Optimal fiber length scale factor ``s_o`` (centre typically 1), or ``l_o - l_o,model`` (m)."""

    type: ClassVar[str] = "optimal_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        return _change(ctx, ctx.optimal_fiber_length_variable, ctx.muscles.optimal_fiber_length)


@attrs.frozen(kw_only=True)
class MtliTendonSlackLength(CostTerm):
    """Tendon slack length scale factor ``s_ts`` (centre typically 1), or ``l_ts - l_ts,model`` (m)."""

    type: ClassVar[str] = "tendon_slack_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        return _change(ctx, ctx.tendon_slack_length_variable, ctx.muscles.tendon_slack_length)


@attrs.frozen(kw_only=True)
class MaximumMuscleStress(CostTerm):
    """Maximum-muscle-stress scale factor ``s_sigma`` (-), 1 when not optimized."""

    type: ClassVar[str] = "maximum_muscle_stress"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        return cs.MX(ctx.stress_scale)

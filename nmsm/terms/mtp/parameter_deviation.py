"""Deviation of MTP's per-muscle parameters from their error centres.

Each term's raw quantity is one value per muscle, reduced as ``sum(z**2) / n_muscles``.
"""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm


def _row(ctx, value):
    return cs.reshape(cs.MX(value) if not isinstance(value, cs.MX) else value, 1, ctx.n_muscles)


@attrs.frozen(kw_only=True)
class ActivationTimeConstant(CostTerm):
    """Activation time constant in seconds (variable / 100); centre typically 0.015 s."""

    type: ClassVar[str] = "activation_time_constant"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return _row(ctx, ctx.design.activation_time_constant) / 100.0


@attrs.frozen(kw_only=True)
class ActivationNonlinearityConstant(CostTerm):
    """Activation nonlinearity constant A (-)."""

    type: ClassVar[str] = "activation_nonlinearity_constant"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return _row(ctx, ctx.design.activation_nonlinearity)


@attrs.frozen(kw_only=True)
class OptimalMuscleFiberLength(CostTerm):
    """Change of optimal fiber length ``l_o s_o - l_o`` (m), l_o the task's starting value."""

    type: ClassVar[str] = "optimal_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        lo = cs.DM(ctx.muscles.optimal_fiber_length.reshape(1, -1))
        return lo * _row(ctx, ctx.design.optimal_fiber_length_scale) - lo


@attrs.frozen(kw_only=True)
class TendonSlackLength(CostTerm):
    """Change of tendon slack length ``l_ts s_ts - l_ts`` (m), l_ts the task's starting value."""

    type: ClassVar[str] = "tendon_slack_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        lts = cs.DM(ctx.muscles.tendon_slack_length.reshape(1, -1))
        return lts * _row(ctx, ctx.design.tendon_slack_length_scale) - lts


@attrs.frozen(kw_only=True)
class EmgScaleFactor(CostTerm):
    """EMG scale factor (-)."""

    type: ClassVar[str] = "emg_scale_factor"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return _row(ctx, ctx.design.emg_scale)

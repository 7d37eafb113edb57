"""MTLI normalized-fiber-length terms (gait trials; per trial ``(n_frames, n_muscles)``)."""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm

#: sharpness of the soft maximum used by the grouped term (the original's 500)
SOFTMAX_SHARPNESS = 500.0


def _extremes(ctx, kind):
    rows = []
    for l in ctx.fiber_length:
        cols = [cs.mmin(l[:, i]) if kind == "min" else cs.mmax(l[:, i]) for i in range(l.shape[1])]
        rows.append(cs.horzcat(*cols))
    return cs.vertcat(*rows)


@attrs.frozen(kw_only=True)
class MtliMinimumNormalizedMuscleFiberLength(CostTerm):
    """``min_t l - l_min`` where below ``min_normalized_muscle_fiber_length``, else 0 (trial x muscle)."""

    type: ClassVar[str] = "minimum_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        return cs.fmin(_extremes(ctx, "min") - ctx.min_normalized_fiber_length, 0)


@attrs.frozen(kw_only=True)
class MtliMaximumNormalizedMuscleFiberLength(CostTerm):
    """``max_t l`` minus the muscle's max-normalized-length variable (trial x muscle)."""

    type: ClassVar[str] = "maximum_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        maxima = _extremes(ctx, "max")
        return maxima - cs.repmat(ctx.max_length_per_muscle(), maxima.shape[0], 1)


@attrs.frozen(kw_only=True)
class MtliGroupedNormalizedMuscleFiberLength(CostTerm):
    """Per grouped muscle: soft maximum over trials and frames of ``|l - group mean of l|``.

    Soft maximum ``log(sum(exp(500 x))) / 500`` (stable log-sum-exp).
    """

    type: ClassVar[str] = "grouped_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        k = SOFTMAX_SHARPNESS
        values = []
        for group in ctx.fiber_length_groups:
            idx = list(group.indices)
            per_trial = []
            for l in ctx.fiber_length:
                members = cs.horzcat(*[l[:, i] for i in idx])
                mean = cs.sum2(members) / len(idx)
                per_trial.append(cs.fabs(members - cs.repmat(mean, 1, len(idx))))
            stacked = cs.vertcat(*per_trial)
            for j in range(len(idx)):
                values.append(cs.logsumexp(k * stacked[:, j]) / k)
        return cs.horzcat(*values) if values else cs.MX(1, 0)


@attrs.frozen(kw_only=True)
class GroupedMaximumNormalizedMuscleFiberLength(CostTerm):
    """``max_normalized_muscle_fiber_length`` setting minus each muscle's max-length variable."""

    type: ClassVar[str] = "grouped_maximum_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        return ctx.max_normalized_fiber_length - ctx.max_length_per_muscle()

"""Normalized-fiber-length terms of MTP.

Arrays are per trial ``(n_frames, n_muscles)``; "initial" lengths are those with unit
scale factors before the first task (the original's ``inputs.normalizedFiberLength``).
"""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm
from nmsm.terms.mtp._base import BlockCostTerm
from nmsm.terms.mtp._helpers import as_dm, columns, mean_of_trials, mean_rows


def _stack(blocks):
    return cs.vertcat(*blocks)


@attrs.frozen(kw_only=True)
class NormalizedMuscleFiberLength(BlockCostTerm):
    """Keeps normalized fiber-length curves close to their initial magnitude and shape.

    Two blocks, each averaged separately: *magnitude* = trial-mean curve minus the initial
    trial-mean curve ``(n_frames, n_muscles)``; *shape* = each curve minus its mean over
    trials and frames, minus the same for the initial curves.
    """

    type: ClassVar[str] = "normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        model = [m.normalized_fiber_length for m in ctx.primary_models]
        initial = as_dm(ctx.initial_fiber_length)
        magnitude = mean_of_trials(model) - mean_of_trials(initial)
        model_all, initial_all = _stack(model), _stack(initial)
        n_rows = model_all.shape[0]
        shape = (model_all - cs.repmat(mean_rows(model_all), n_rows, 1)) - (
            initial_all - cs.repmat(mean_rows(initial_all), n_rows, 1)
        )
        return (magnitude, shape)


@attrs.frozen(kw_only=True)
class GroupedNormalizedMuscleFiberLength(BlockCostTerm):
    """Similar normalized fiber lengths within ``<normalized_fiber_length_muscle_groups>``.

    Per group: *magnitude* = (mean l of a member - its initial mean) minus the group
    average of that change, one value per member; *shape* = each member's curve minus its
    mean, minus the group average of those centred curves. Groups concatenated; the two
    blocks averaged separately.
    """

    type: ClassVar[str] = "grouped_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        model = _stack([m.normalized_fiber_length for m in ctx.primary_models])
        initial = _stack(as_dm(ctx.initial_fiber_length))
        n_rows = model.shape[0]
        magnitudes, shapes = [], []
        for group in ctx.fiber_length_groups:
            mod = columns(model, group.indices)
            ini = columns(initial, group.indices)
            change = mean_rows(mod) - mean_rows(ini)
            k = len(group.indices)
            magnitudes.append(change - cs.sum2(change) / k)
            centred = mod - cs.repmat(mean_rows(mod), n_rows, 1)
            shapes.append(centred - cs.repmat(cs.sum2(centred) / k, 1, k))
        if not magnitudes:
            return (cs.MX(1, 0), cs.MX(n_rows, 0))
        return (cs.horzcat(*magnitudes), cs.horzcat(*shapes))


def _extreme(ctx, kind):
    """Per trial and muscle the min or max over frames: (n_trials, n_muscles)."""
    rows = []
    for m in ctx.primary_models:
        l = m.normalized_fiber_length
        cols = [cs.mmin(l[:, i]) if kind == "min" else cs.mmax(l[:, i]) for i in range(l.shape[1])]
        rows.append(cs.horzcat(*cols))
    return cs.vertcat(*rows)


@attrs.frozen(kw_only=True)
class MinimumNormalizedMuscleFiberLength(CostTerm):
    """How far each trial's minimum normalized fiber length falls below the task minimum.

    ``min(min_t l - l_min, 0)`` per trial and muscle (``l_min`` = the task's
    ``min_normalized_muscle_fiber_length``, 0.75 by default). The original uses the minimum
    itself where it is below the limit (a cost that jumps at the limit); the deviation is
    what the term is meant to penalize.
    """

    type: ClassVar[str] = "minimum_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return cs.fmin(_extreme(ctx, "min") - ctx.min_normalized_fiber_length, 0)


@attrs.frozen(kw_only=True)
class MaximumNormalizedMuscleFiberLength(CostTerm):
    """How far each trial's maximum normalized fiber length exceeds the task maximum.

    ``max(max_t l - l_max, 0)`` per trial and muscle (``l_max`` default 1.05); see
    :class:`MinimumNormalizedMuscleFiberLength` for the difference from the original.
    """

    type: ClassVar[str] = "maximum_normalized_muscle_fiber_length"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return cs.fmax(_extreme(ctx, "max") - ctx.max_normalized_fiber_length, 0)

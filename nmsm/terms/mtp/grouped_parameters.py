"""Similarity of EMG scale factors and electromechanical delays within activation groups.

Raw quantity: each member's value minus its group's mean, groups concatenated in settings
order (``<activation_muscle_groups>``); reduced as ``sum(z**2) / numel``.
"""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm
from nmsm.terms.mtp._helpers import minus_mean


def _group_deviations(ctx, row):
    parts = []
    for group in ctx.activation_groups:
        members = cs.horzcat(*[row[:, i] for i in group.indices])
        parts.append(minus_mean(members))
    return cs.horzcat(*parts) if parts else cs.MX(1, 0)


@attrs.frozen(kw_only=True)
class GroupedEmgScaleFactor(CostTerm):
    """EMG scale factor minus its activation group's mean (-)."""

    type: ClassVar[str] = "grouped_emg_scale_factor"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        row = cs.reshape(cs.MX(ctx.design.emg_scale), 1, ctx.n_muscles)
        return _group_deviations(ctx, row)


@attrs.frozen(kw_only=True)
class GroupedElectromechanicalDelay(CostTerm):
    """Electromechanical delay (s, variable / 10) minus its activation group's mean."""

    type: ClassVar[str] = "grouped_electromechanical_delay"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        row = cs.reshape(cs.MX(ctx.design.electromechanical_delay), 1, ctx.n_muscles) / 10.0
        return _group_deviations(ctx, row)

"""MTLI ``passive_muscle_force``: passive tendon forces of the gait trials (N)."""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class MtliPassiveMuscleForce(CostTerm):
    """Penalizes passive muscle force (N) over gait trials, frames and muscles."""

    type: ClassVar[str] = "passive_muscle_force"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def quantity(self, ctx):
        return cs.vertcat(*ctx.passive_force)

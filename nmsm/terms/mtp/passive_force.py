"""``passive_muscle_force``: passive tendon force ``F0 f_P(l) cos(alpha)`` (N) of every muscle and frame."""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class PassiveMuscleForce(CostTerm):
    """Penalizes passive muscle force (N), all trials, frames and muscles."""

    type: ClassVar[str] = "passive_muscle_force"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return cs.vertcat(*[m.passive_force for m in ctx.primary_models])

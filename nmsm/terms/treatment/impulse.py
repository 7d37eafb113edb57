"""Braking and propulsive impulse goals (DO, discrete; docs/terms.md).

``propulsive_impulse_goal``  ``I = ∫ max(F_x, 0) dt`` of one foot (N·s)
``braking_impulse_goal``     ``I = ∫ max(-F_x, 0) dt``
``F_x``: forward (ground x) ground reaction force of the contact models acting on
``<hindfoot_body>`` (``<hindfoot_body_list>``: one term per foot), on the collocation points
with the phase's quadrature. The objective gets ``((I - c)/e)²``; ``error_center`` is
required. ``normalize_by_final_time`` (default false) divides by ``t_f``: the mean force
(N), which is what the original's τ-integral (normalized time) computes.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import DiscreteCost


@attrs.frozen(kw_only=True)
class _ImpulseGoal(DiscreteCost):
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    sign: ClassVar[float] = 1.0
    #: a target for nmsm.testing.check_term (its leg's foot is pushed backwards by the belt)
    check_example: ClassVar[Mapping[str, str]] = {"error_center": "100"}
    hindfoot_body: str
    error_center: float | None = None  # required (checked in bind)
    normalize_by_final_time: bool = False

    def bind(self, ctx: Any) -> None:
        if self.error_center is None:
            raise self.error("needs <error_center> (the target impulse)", element="<error_center>",
                             expected="a number (N·s)")
        ctx.require_hindfoot_body(self, self.hindfoot_body)

    def quantity(self, ctx: Any) -> Any:
        force, _, _ = ctx.foot_ground_reaction(self.hindfoot_body)
        mean = ctx.integrate(cs.fmax(self.sign * force[:, 0], 0))
        return mean if self.normalize_by_final_time else mean * ctx.final_time


@attrs.frozen(kw_only=True)
class PropulsiveImpulseGoal(_ImpulseGoal):
    """Drives a foot's propulsive impulse ∫max(F_x, 0)dt (N·s) to ``error_center``."""

    type: ClassVar[str] = "propulsive_impulse_goal"


@attrs.frozen(kw_only=True)
class BrakingImpulseGoal(_ImpulseGoal):
    """Drives a foot's braking impulse ∫max(-F_x, 0)dt (N·s) to ``error_center``."""

    type: ClassVar[str] = "braking_impulse_goal"
    sign: ClassVar[float] = -1.0

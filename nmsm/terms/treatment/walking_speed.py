"""``relative_walking_speed_goal`` (DO, discrete; docs/terms.md, docs/treatment.md).

``v = (c_x(t_f) - c_x(0)) / t_f``: mean forward (ground x) speed of the whole-body centre of
mass over the movement (m/s), relative to the model's ground (the belt, on a treadmill); the
objective gets ``((v - c)/e)²``. The original computes ``(ċ_x(t_f) - ċ_x(0)) / t_f`` (a change
of COM velocity, not a speed), and only on Windows; this is the intended mean
speed.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.ocp import DiscreteCost


def mean_forward_speed(ctx: Any) -> Any:
    """Mean forward speed of the centre of mass (m/s), an MX scalar."""
    return (ctx.final.center_of_mass_position()[0, 0] - ctx.initial.center_of_mass_position()[0, 0]) / ctx.final_time


@attrs.frozen(kw_only=True)
class RelativeWalkingSpeedGoal(DiscreteCost):
    """Drives the mean forward centre-of-mass speed (m/s) to ``error_center``."""

    type: ClassVar[str] = "relative_walking_speed_goal"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})

    def bind(self, ctx: Any) -> None:
        ctx.require_whole_body(self)

    def quantity(self, ctx: Any) -> Any:
        return mean_forward_speed(ctx)

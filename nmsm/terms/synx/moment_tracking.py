"""``measured_inverse_dynamics_joint_moment``: moments with SynX activations minus ID (N m)."""

from __future__ import annotations

from typing import ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class MeasuredInverseDynamicsJointMoment(CostTerm):
    """Tracks inverse-dynamics moments with the activations including extrapolated muscles (N m)."""

    type: ClassVar[str] = "measured_inverse_dynamics_joint_moment"
    tools: ClassVar[frozenset[str]] = frozenset({"SynX"})

    def quantity(self, ctx):
        return ctx.moment_errors(synx=True)

"""``inverse_dynamics_joint_moment``: modeled minus inverse-dynamics joint moments (N m)."""

from __future__ import annotations

from typing import ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class InverseDynamicsJointMoment(CostTerm):
    """Tracks inverse-dynamics moments with the EMG-driven model (no SynX activations), N m.

    Raw quantity: ``M_model - M_ID`` over trials, frames and tracked coordinates; reduced
    as ``sum(z**2) / numel``.
    """

    type: ClassVar[str] = "inverse_dynamics_joint_moment"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})

    def quantity(self, ctx):
        return ctx.moment_errors(synx=False)

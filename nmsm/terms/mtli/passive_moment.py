"""``passive_joint_moment``: modeled passive joint moments minus passive-trial ID moments (N m)."""

from __future__ import annotations

from typing import ClassVar

import attrs
import casadi as cs
import numpy as np

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class PassiveJointMoment(CostTerm):
    """Tracks passive-trial moments; ID columns that are zero in the whole trial are left out."""

    type: ClassVar[str] = "passive_joint_moment"
    tools: ClassVar[frozenset[str]] = frozenset({"MTLI"})

    def bind(self, ctx):
        if not ctx.has_passive_data:
            raise self.error(
                "needs passive data",
                element="<passive_data_input_directory>",
                expected="a folder with IDData/ and MAData/ of passive trials",
            )

    def quantity(self, ctx):
        parts = []
        for trial, model in zip(ctx.passive_trials, ctx.passive_moments):
            measured = trial.inverse_dynamics_moments
            for c in np.flatnonzero(np.any(measured != 0, axis=0)):
                parts.append(model[:, int(c)] - cs.DM(measured[:, c]))
        return cs.vertcat(*parts) if parts else cs.MX(0, 1)

"""``muscle_excitation_penalty``: keeps SynX excitations of measured muscles away from extremes.

Residual per sample: ``sqrt(0.1) * (30 / e) * (u - c)**8`` on the undelayed excitations of
the measured muscles inside the un-padded window, summed (no averaging); with the usual
``e = 0.25``, ``c = 0.5`` this is the original's ``120 (u - 0.5)^8``. Only active with
Synergy Extrapolation (as in the original).
"""

from __future__ import annotations

import math
from typing import ClassVar

import attrs
import casadi as cs

from nmsm.core.term import CostTerm
from nmsm.terms.mtp._helpers import columns


@attrs.frozen(kw_only=True)
class MuscleExcitationPenalty(CostTerm):
    """Eighth-power penalty on measured muscles' excitations (-)."""

    type: ClassVar[str] = "muscle_excitation_penalty"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP", "SynX"})
    reduction: ClassVar[str] = "plain"

    def quantity(self, ctx):
        if not ctx.synx_enabled:
            return cs.MX(0, 1)
        n = ctx.models[0].activations.shape[0]
        pad = ctx.padding
        blocks = [columns(m.excitations_undelayed[pad : pad + n, :], ctx.measured) for m in ctx.synx_models]
        return cs.vertcat(*blocks)

    def normalized(self, ctx):
        u = self.quantity(ctx)
        if u.numel() == 0:
            return u
        return math.sqrt(0.1) * (30.0 / self.max_allowable_error) * (u - self.error_center) ** 8

"""Base of MTP terms whose raw quantity has several blocks averaged separately."""

from __future__ import annotations

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class BlockCostTerm(CostTerm):
    """``quantity`` returns a tuple of blocks; each is normalized and reduced on its own."""

    def normalized(self, ctx):
        blocks = self.quantity(ctx)
        return tuple((b - self.error_center) / self.max_allowable_error for b in blocks)

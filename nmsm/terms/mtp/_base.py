"""Base of MTP terms whose raw quantity has several blocks averaged separately."""

from __future__ import annotations

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class BlockCostTerm(CostTerm):
    """``quantity`` returns a tuple of blocks; each is normalized (by :meth:`CostTerm.normalized`)
    and reduced on its own."""

"""Base of GCP terms: one raw block per foot, each normalized and reduced on its own."""

from __future__ import annotations

from typing import Any

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class FootCostTerm(CostTerm):
    """A GCP cost term; subclasses define :meth:`foot_quantity` (raw block of one foot)."""

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        """The raw quantity of foot ``foot`` (0-based). Override."""
        raise NotImplementedError(f"{type(self).__name__}.foot_quantity")

    def quantity(self, ctx: Any) -> tuple[Any, ...]:
        """One raw block per foot (the base class normalizes each block)."""
        return tuple(self.foot_quantity(ctx, foot) for foot in range(ctx.n_feet))

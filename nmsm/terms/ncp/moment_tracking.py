"""``moment_tracking``: muscle joint moments minus inverse-dynamics loads."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class MomentTracking(CostTerm):
    """``M_mod - M_ID`` (N·m; N for translational coordinates) over trials, coordinates, frames.

    ``M_mod`` is computed from the NCP activations with the MTP-personalized muscle model.
    """

    type: ClassVar[str] = "moment_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.moment_errors()

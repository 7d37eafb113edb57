"""``activation_tracking``: NCP activations minus MTP activations."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class ActivationTracking(CostTerm):
    """``a_NCP - a_MTP`` (-) for the muscles with MTP activations; one zero when there are none."""

    type: ClassVar[str] = "activation_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.activation_tracking_errors()

"""``grouped_activations``: activations similar within each activation muscle group."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class GroupedActivations(CostTerm):
    """``a - mean over the group`` (-) per frame, for each ``activation_muscle_groups`` group."""

    type: ClassVar[str] = "grouped_activations"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.grouped_deviations(ctx.inputs.activation_groups)

"""``activation_minimization``: activations of muscles without MTP activations."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class ActivationMinimization(CostTerm):
    """``a - error_center`` (-) for the muscles without MTP activations (all muscles when NCP
    runs without MTP results; nothing when every muscle has MTP activations)."""

    type: ClassVar[str] = "activation_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.untracked_activations()

"""``synergy_weight_sum``: each synergy vector of a group sums to a constant (NCP).

docs/ncp.md: the weights of every synergy vector of group ``g`` sum to ``M_g / 100``
(``M_g`` muscles in the group), which removes the scale ambiguity between vectors and
commands. NCP adds one of these per group whose vectors are design variables; it is not
declared in settings.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import ConstraintTerm


@attrs.frozen(kw_only=True)
class SynergyWeightSum(ConstraintTerm):
    """``Σ_m W_g[s, m] - target`` (S_g,) bounded by ``[min_error, max_error]`` (default 0, 0).

    ``group`` is the synergy group's index in the layout, ``target`` the constant (``M_g/100``).
    """

    type: ClassVar[str] = "synergy_weight_sum"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    group: int = 0
    target: float = 0.0
    max_error: float = 0.0
    min_error: float = 0.0

    def value(self, ctx: Any) -> Any:
        return ctx.weight_row_sums(self.group) - self.target

    @property
    def label(self) -> str:
        return f"{self.type}:{self.name or self.group}"

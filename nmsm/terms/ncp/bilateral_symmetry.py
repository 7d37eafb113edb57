"""``bilateral_symmetry``: synergy vectors of the two synergy groups alike (soft form).

``enforce_bilateral_symmetry`` shares the vectors exactly (the term is then zero); this
term is the soft alternative of the original's 2023 settings (``max_allowable_error`` 1e-3).
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class BilateralSymmetry(CostTerm):
    """``W_group1 - W_group2`` (-), muscles paired with their mirror (``_r``/``_l``)."""

    type: ClassVar[str] = "bilateral_symmetry"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.symmetry_difference()

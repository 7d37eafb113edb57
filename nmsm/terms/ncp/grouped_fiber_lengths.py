"""``grouped_fiber_lengths``: activations similar within each normalized-fiber-length group.

As in the MATLAB original, the deviation is computed on the **activations**
of the ``normalized_fiber_length_muscle_groups``: NCP's normalized fiber lengths are data
(they do not depend on the design variables), so a deviation of fiber lengths would be a
constant.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class GroupedFiberLengths(CostTerm):
    """``a - mean over the group`` (-) per frame, for each normalized-fiber-length group."""

    type: ClassVar[str] = "grouped_fiber_lengths"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.grouped_deviations(ctx.inputs.fiber_length_groups)

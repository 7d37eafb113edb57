"""``angular_momentum_minimization`` (DO; docs/terms.md, the intended math).

Integrand component ``g = H_axis / t_f``: ``H`` is the whole-body angular momentum about the
centre of mass in ground axes (kg·m²/s; ``Σ m_i (c_i - c) × (v_i - ċ) + I_i ω_i``), ``axis``
from ``<axes>`` (one term per axis), ``t_f`` the final time (s). The objective gets
``∫₀¹ ((g - c)/e)² ds``. (The original's term references undefined variables and cannot run;
this is the catalog's intended math, division by ``t_f`` included.)
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.ocp import ContinuousCost, require_axis


@attrs.frozen(kw_only=True)
class AngularMomentumMinimization(ContinuousCost):
    """Minimizes one component of the whole-body central angular momentum, ``H_axis / t_f``."""

    type: ClassVar[str] = "angular_momentum_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    axis: str | None = None

    def bind(self, ctx: Any) -> None:
        require_axis(self, self.axis)
        ctx.require_whole_body(self)

    def quantity(self, ctx: Any) -> Any:
        return ctx.angular_momentum()[:, "xyz".index(self.axis)] / ctx.final_time

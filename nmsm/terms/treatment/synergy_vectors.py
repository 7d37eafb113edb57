"""Synergy vector costs (docs/terms.md; discrete; synergy controller).

``synergy_vector_tracking``  ‖w_s - w_s,init‖₂ over the group's muscles (the original does not
                             divide it by max_allowable_error; here it is normalized like every
                             term: ((value - c)/e)²)
``synergy_vector_symmetry``  mean over muscles of ((v1 - v2 - c)/e)² for the two synergies named
                             in ``<synergies>`` (groups of equal size, muscles matched by order)
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import DiscreteCost


@attrs.frozen(kw_only=True)
class SynergyVectorTracking(DiscreteCost):
    """Distance of a synergy vector from its initial value (weights, dimensionless)."""

    type: ClassVar[str] = "synergy_vector_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    synergy: str

    def bind(self, ctx: Any) -> None:
        ctx.require_synergy(self, self.synergy)

    def quantity(self, ctx: Any) -> Any:
        w = cs.MX(ctx.synergy_vector(self.synergy))
        w0 = cs.DM(ctx.synergy_vector(self.synergy, initial=True))
        return cs.sqrt(cs.sumsqr(w - w0) + 1e-12)


@attrs.frozen(kw_only=True)
class SynergyVectorSymmetry(DiscreteCost):
    """Mean squared normalized difference of two synergy vectors."""

    type: ClassVar[str] = "synergy_vector_symmetry"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    synergies: tuple[str, ...]

    def bind(self, ctx: Any) -> None:
        if len(self.synergies) != 2:
            raise self.error(f"needs two synergies, got {len(self.synergies)}", element="<synergies>",
                             expected="two synergy names <group>_<k>")
        for name in self.synergies:
            ctx.require_synergy(self, name, element="<synergies>")
        a, b = (cs.MX(ctx.synergy_vector(n)) for n in self.synergies)
        if a.numel() != b.numel():
            raise self.error("the two synergies' groups have different numbers of muscles", element="<synergies>")

    def residuals(self, ctx: Any) -> Any:
        a, b = (cs.MX(ctx.synergy_vector(n)) for n in self.synergies)
        z = (cs.vec(a - b) - self.error_center) / self.max_allowable_error
        return z / (z.numel() ** 0.5)

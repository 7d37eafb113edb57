"""Synergy vector constraints (docs/terms.md; terminal; synergy controller, TO/DO).

``synergy_vector_sum``       Σ_j w_sj of synergy ``<synergy>`` (``<group>_<k>``)
``synergy_vector_magnitude`` ‖w_s‖₂
``synergy_vector_symmetry``  smooth max over muscles of |v1 - v2| (log-sum-exp with
                             k = 700 / max|w_init|), ``<synergies>`` = two names
(The reference XML lists ``<synergy_group_list>``, which the original's functions do not read;
use ``<synergy_list>`` / ``<synergy>``.)
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs
import numpy as np

from nmsm.core.ocp import TerminalConstraint

SYNERGY_TOOLS = frozenset({"TO", "DO"})


@attrs.frozen(kw_only=True)
class SynergyVectorSum(TerminalConstraint):
    """Sum of a synergy vector's weights."""

    type: ClassVar[str] = "synergy_vector_sum"
    tools: ClassVar[frozenset[str]] = SYNERGY_TOOLS
    synergy: str

    def bind(self, ctx: Any) -> None:
        ctx.require_synergy(self, self.synergy)

    def value(self, ctx: Any) -> Any:
        return cs.sum2(cs.MX(ctx.synergy_vector(self.synergy)))


@attrs.frozen(kw_only=True)
class SynergyVectorMagnitude(TerminalConstraint):
    """Euclidean norm of a synergy vector."""

    type: ClassVar[str] = "synergy_vector_magnitude"
    tools: ClassVar[frozenset[str]] = SYNERGY_TOOLS
    synergy: str

    def bind(self, ctx: Any) -> None:
        ctx.require_synergy(self, self.synergy)

    def value(self, ctx: Any) -> Any:
        return cs.sqrt(cs.sumsqr(cs.MX(ctx.synergy_vector(self.synergy))) + 1e-12)


@attrs.frozen(kw_only=True)
class SynergyVectorSymmetryConstraint(TerminalConstraint):
    """Smooth maximum absolute difference between two synergy vectors."""

    type: ClassVar[str] = "synergy_vector_symmetry"
    tools: ClassVar[frozenset[str]] = SYNERGY_TOOLS
    synergies: tuple[str, ...]

    def bind(self, ctx: Any) -> None:
        if len(self.synergies) != 2:
            raise self.error(f"needs two synergies, got {len(self.synergies)}", element="<synergies>",
                             expected="two synergy names <group>_<k>")
        for name in self.synergies:
            ctx.require_synergy(self, name, element="<synergies>")

    def value(self, ctx: Any) -> Any:
        a, b = (cs.vec(cs.MX(ctx.synergy_vector(n))) for n in self.synergies)
        initial = np.concatenate([np.ravel(ctx.synergy_vector(n, initial=True)) for n in self.synergies])
        k = 700.0 / max(float(np.max(np.abs(initial))), 1e-12)
        d = cs.sqrt((a - b) ** 2 + 1e-12)
        return cs.logsumexp(k * d) / k

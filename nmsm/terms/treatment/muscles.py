"""Muscle activation costs (docs/terms.md); muscles driven by a synergy or muscle controller.

``muscle_activation_tracking``      scale·a_exp - a   (a_exp: ``<trial>_combinedActivations.sto``
                                    of the initial guess directory)
``muscle_activation_minimization``  integrand (a/e)^p with p = ``exponent`` (default 2)
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import ContinuousCost


@attrs.frozen(kw_only=True)
class MuscleActivationTracking(ContinuousCost):
    """Tracks a muscle activation: scale·a_exp - a (0..1)."""

    type: ClassVar[str] = "muscle_activation_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    muscle: str
    scale_factor: float = 1.0

    def bind(self, ctx: Any) -> None:
        ctx.require_tracked_activation(self, self.muscle)

    def quantity(self, ctx: Any) -> Any:
        return self.scale_factor * ctx.tracked_muscle_activation(self.muscle) - ctx.muscle_activation(self.muscle)


@attrs.frozen(kw_only=True)
class MuscleActivationMinimization(ContinuousCost):
    """Minimizes a muscle activation: integrand (a/e)^exponent."""

    type: ClassVar[str] = "muscle_activation_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    muscle: str
    exponent: float = 2.0

    def bind(self, ctx: Any) -> None:
        ctx.require_muscle(self, self.muscle)
        if self.error_center != 0:
            raise self.error("muscle_activation_minimization takes no error_center", element="<error_center>",
                             expected="0 or absent")

    def quantity(self, ctx: Any) -> Any:
        a = ctx.muscle_activation(self.muscle)
        e = self.max_allowable_error
        return e * cs.power(cs.fmax(a, 0) / e, self.exponent / 2.0)

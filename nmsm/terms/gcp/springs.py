"""Spring-constant regularization: ``spring_constant_mean``, ``neighbor_spring_constant``."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.gcp._base import FootCostTerm


@attrs.frozen(kw_only=True)
class SpringConstantMean(FootCostTerm):
    """Spring constants minus their mean (N/m); repeated per foot as in the original."""

    type: ClassVar[str] = "spring_constant_mean"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.spring_constants_minus_mean()


@attrs.frozen(kw_only=True)
class NeighborSpringConstant(FootCostTerm):
    """Each spring constant minus the Gaussian-weighted mean of the others (N/m), every frame
    (weights ``exp(-d^2/(2 sigma^2))`` of the 3-D spring distances; sigma the task's
    ``neighborStandardDeviation``).

    Non-standard normalization (as the original's GCP): the residual is ``((raw - c)/e)^4``, so
    deviations below ``e`` are nearly free and larger ones grow steeply.
    """

    type: ClassVar[str] = "neighbor_spring_constant"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.neighbor_deviation(foot)

    def normalized(self, ctx: Any) -> tuple[Any, ...]:
        return tuple(z**4 for z in super().normalized(ctx))

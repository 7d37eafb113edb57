"""Foot-coordinate tracking: ``rotation``, ``translation``, ``kinematic_periodicity``."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.terms.gcp._base import FootCostTerm


@attrs.frozen(kw_only=True)
class Rotation(FootCostTerm):
    """Modeled minus experimental toe angle and hindfoot rotations (rad), every frame."""

    type: ClassVar[str] = "rotation"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.coordinate_errors(foot, slice(0, 4))


@attrs.frozen(kw_only=True)
class Translation(FootCostTerm):
    """Modeled minus experimental hindfoot origin (m), every frame."""

    type: ClassVar[str] = "translation"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.coordinate_errors(foot, slice(4, 7))


@attrs.frozen(kw_only=True)
class KinematicPeriodicity(FootCostTerm):
    """``(q(t0) - q(tf)) / max(|q_exp(t0) - q_exp(tf)|, (0.0175 rad x4, 0.001 m x3))``
    (dimensionless) of the seven foot coordinates."""

    type: ClassVar[str] = "kinematic_periodicity"
    tools: ClassVar[frozenset[str]] = frozenset({"GCP"})

    def foot_quantity(self, ctx: Any, foot: int) -> Any:
        return ctx.periodicity(foot)

"""SynX activation terms: extrapolated activations and residual activations."""

from __future__ import annotations

from typing import ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class ExtrapolatedMuscleActivation(CostTerm):
    """Activations of the muscles without EMG (from synergies), all trials and frames (-)."""

    type: ClassVar[str] = "extrapolated_muscle_activation"
    tools: ClassVar[frozenset[str]] = frozenset({"SynX"})

    def quantity(self, ctx):
        return ctx.stacked("activations", synx=True, columns=ctx.missing)


@attrs.frozen(kw_only=True)
class ResidualMuscleActivation(CostTerm):
    """SynX minus EMG-only activations of the measured muscles (the residual's effect) (-)."""

    type: ClassVar[str] = "residual_muscle_activation"
    tools: ClassVar[frozenset[str]] = frozenset({"SynX"})

    def quantity(self, ctx):
        return ctx.stacked("activations", synx=True, columns=ctx.measured) - ctx.stacked(
            "activations", synx=False, columns=ctx.measured
        )

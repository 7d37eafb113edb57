"""Ground reaction costs (docs/terms.md; contact models, TO/DO).

``external_force_tracking``   F_exp - F of one force column (N) of a contact surface
``external_moment_tracking``  M_exp - M of one moment column (N·m), both about the surface's
                              reference point (GCP: midfoot-superior marker on the floor; the
                              experimental torque is moved there from the electrical centre)
Options: ``time_ranges``, ``use_relative_error`` + ``min_reference_value`` (default 1): the
error is divided by ``max(|reference|, min_reference_value)``.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import ContinuousCost


@attrs.frozen(kw_only=True)
class _ReactionTracking(ContinuousCost):
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    use_relative_error: bool = False
    min_reference_value: float = 1.0

    def _label(self) -> str:
        raise NotImplementedError

    def bind(self, ctx: Any) -> None:
        ctx.require_reaction(self, self._label(), self.kind_name, f"<{self.kind_name}_list>")
        if not ctx.has_tracked_ground_reaction(self._label()):
            raise self.error(f"no column '{self._label()}' in the tracked ground reactions (GRFData)",
                             element=f"<{self.kind_name}_list>")

    def _relative(self, error: Any, reference: Any) -> Any:
        if not self.use_relative_error:
            return error
        return error / cs.fmax(cs.fabs(reference), self.min_reference_value)


@attrs.frozen(kw_only=True)
class ExternalForceTracking(_ReactionTracking):
    """Tracks a ground reaction force component: F_exp - F (N)."""

    type: ClassVar[str] = "external_force_tracking"
    kind_name: ClassVar[str] = "force"
    force: str

    def _label(self) -> str:
        return self.force

    def quantity(self, ctx: Any) -> Any:
        reference = cs.MX(ctx.tracked_ground_reaction_force(self.force))
        return self._relative(reference - ctx.ground_reaction_force(self.force), reference)


@attrs.frozen(kw_only=True)
class ExternalMomentTracking(_ReactionTracking):
    """Tracks a ground reaction moment component: M_exp - M (N·m)."""

    type: ClassVar[str] = "external_moment_tracking"
    kind_name: ClassVar[str] = "moment"
    moment: str

    def _label(self) -> str:
        return self.moment

    def quantity(self, ctx: Any) -> Any:
        reference = cs.MX(ctx.tracked_ground_reaction_moment(self.moment))
        return self._relative(reference - ctx.ground_reaction_moment(self.moment), reference)

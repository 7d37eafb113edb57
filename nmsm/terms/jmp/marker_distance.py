"""JMP's cost: marker distance errors after inverse kinematics.

``marker_distance_error``: for every frame ``f`` and marker ``m`` of a task, the vector
``sqrt(w_m) (x_m(q_f, p) - x_m,exp(t_f))`` (m, ground frame; zero in gaps). Divided by
``max_allowable_error`` (the settings' ``<allowable_error>``) and reduced by the JMP tool to
``1/sqrt(n_obs)`` per entry, its squared sum is

    sum_f sum_m w_m |d_fm|^2 / (n_obs * allowable_error^2)

with ``n_obs`` the number of marker observations (markers x frames, gaps excluded): the
original's ``d_fm / sqrt(M) / sqrt(F) / allowable_error`` residuals, whose squared sum
equals this when there are no gaps. Using the three components rather than the distance
keeps the residual smooth at zero error; the objective is the same.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.term import CostTerm


@attrs.frozen(kw_only=True)
class MarkerDistanceError(CostTerm):
    """Weighted marker position errors after IK: x_model - x_exp (m), every frame and marker."""

    type: ClassVar[str] = "marker_distance_error"
    tools: ClassVar[frozenset[str]] = frozenset({"JMP"})

    def bind(self, ctx: Any) -> None:
        if ctx.n_observations == 0:
            raise self.error("the task has no marker observation in its time range",
                             expected="marker data in the task's time range")

    def quantity(self, ctx: Any) -> Any:
        return ctx.marker_position_errors()

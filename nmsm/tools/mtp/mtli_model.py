"""Muscle-Tendon Length Initialization (MTLI): modeled quantities and term context.

Design variables (docs/mtp.md), as CasADi expressions:

* ``optimal_fiber_length``: scale factors ``s_o`` (init 1, [0.5, 2]) or absolute lengths
  (m, [0.001, 2]) when ``optimize_absolute_length_changes``;
* ``tendon_slack_length``: likewise;
* ``max_normalized_length``: one per normalized-fiber-length group, then one per muscle
  in no group (muscle order) (init 1, [1, 1.2]);
* ``stress_scale``: maximum-muscle-stress scale ``s_sigma`` (init 1, [0.6, 2.3]) when
  ``optimize_maximum_muscle_stress``.

Modeled: normalized fiber lengths of the gait trials ``(n_frames, n_muscles)`` per trial,
passive tendon forces from them, and passive joint moments of the passive trials
``(n_frames, n_coordinates)``. With ``optimize_isometric_max_force``,
``F0 = V / l_o * sigma0 * s_sigma`` with the muscle volume ``V = F0_model l_o_model / sigma0``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.model import hill
from nmsm.tools.mtp.context import reduce_blocks
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters


@attrs.frozen(eq=False)
class PassiveTrial:
    """A passive trial: muscle-tendon lengths (n, M) m, moment arms (n, C, M) m, ID moments (n, C) N m."""

    name: str
    time: np.ndarray
    muscle_tendon_length: np.ndarray
    moment_arms: np.ndarray
    inverse_dynamics_moments: np.ndarray


def max_length_variable_index(n_muscles: int, groups: Sequence[MuscleGroup]) -> np.ndarray:
    """Index of each muscle's max-normalized-length variable: groups first, then ungrouped muscles."""
    index = np.full(n_muscles, -1, dtype=int)
    for g, group in enumerate(groups):
        for i in group.indices:
            if index[i] < 0:
                index[i] = g
    k = len(groups)
    for i in range(n_muscles):
        if index[i] < 0:
            index[i] = k
            k += 1
    return index


@attrs.define(eq=False)
class MtliContext:
    """What MTLI terms read. Arrays per trial; CasADi MX for modeled quantities.

    ``optimal_fiber_length_variable`` / ``tendon_slack_length_variable``: the design rows
    (scale factors, or absolute lengths in absolute mode); ``initial_*``: model values (m).
    """

    muscles: MuscleParameters
    absolute_lengths: bool
    optimal_fiber_length_variable: Any
    tendon_slack_length_variable: Any
    max_normalized_length: Any
    stress_scale: Any
    variable_of_muscle: np.ndarray
    fiber_length: list[Any]
    passive_force: list[Any]
    passive_moments: list[Any]
    passive_trials: tuple[PassiveTrial, ...]
    fiber_length_groups: tuple[MuscleGroup, ...]
    min_normalized_fiber_length: float
    max_normalized_fiber_length: float
    tool: str = "MTLI"

    def reduce_cost(self, term: Any, normalized: Any) -> Any:
        return reduce_blocks(term, normalized)

    def reduce_constraint(self, term: Any, value: Any) -> tuple[Any, Any, Any]:
        return value, term.min_error, term.max_error

    @property
    def has_passive_data(self) -> bool:
        return bool(self.passive_trials)

    def max_length_per_muscle(self) -> Any:
        """The max-normalized-length variable of each muscle, ``(1, n_muscles)``."""
        return cs.horzcat(*[self.max_normalized_length[int(k)] for k in self.variable_of_muscle])


def mtli_quantities(
    muscles: MuscleParameters,
    gait_lengths: Sequence[np.ndarray],
    passive_trials: Sequence[PassiveTrial],
    *,
    optimal_fiber_length: Any,
    tendon_slack_length: Any,
    stress_scale: Any,
    absolute_lengths: bool,
    update_max_isometric_force: bool,
    maximum_muscle_stress: float,
) -> tuple[Any, list[Any], list[Any], list[Any]]:
    """``(F0 (1, M), fiber lengths per gait trial, passive forces per gait trial, passive moments per passive trial)``."""
    m = muscles.n_muscles
    lo0 = cs.DM(muscles.optimal_fiber_length.reshape(1, m))
    lts0 = cs.DM(muscles.tendon_slack_length.reshape(1, m))
    lo_var = cs.reshape(cs.MX(optimal_fiber_length), 1, m)
    lts_var = cs.reshape(cs.MX(tendon_slack_length), 1, m)
    lo = lo_var if absolute_lengths else lo0 * lo_var
    lts = lts_var if absolute_lengths else lts0 * lts_var
    alpha = cs.DM(muscles.pennation_angle.reshape(1, m))
    if update_max_isometric_force:
        volume = hill.muscle_volume(muscles.max_isometric_force, muscles.optimal_fiber_length, maximum_muscle_stress)
        f0 = cs.DM(volume.reshape(1, m)) / lo * maximum_muscle_stress * cs.MX(stress_scale)
    else:
        f0 = cs.MX(cs.DM(muscles.max_isometric_force.reshape(1, m)))

    def lengths(lmt: np.ndarray) -> Any:
        n = lmt.shape[0]
        return hill.normalized_fiber_length(cs.DM(lmt), cs.repmat(lo, n, 1), cs.repmat(lts, n, 1), cs.repmat(alpha, n, 1))

    def passive(l: Any) -> Any:
        n = l.shape[0]
        return hill.passive_tendon_force(l, cs.repmat(f0, n, 1), cs.repmat(alpha, n, 1))

    fiber = [lengths(x) for x in gait_lengths]
    forces = [passive(l) for l in fiber]
    moments = []
    for trial in passive_trials:
        fp = passive(lengths(trial.muscle_tendon_length))
        cols = [cs.sum2(cs.DM(trial.moment_arms[:, c, :]) * fp) for c in range(trial.moment_arms.shape[1])]
        moments.append(cs.horzcat(*cols))
    return f0, fiber, forces, moments

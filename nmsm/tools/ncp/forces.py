"""Muscle moments as a linear function of activations (fixed kinematics).

In NCP the muscle-tendon lengths and velocities are data, so each muscle's tendon force
is affine in its activation: ``F = a * F_active + F_passive`` with (Hill model,
:mod:`nmsm.model.hill`)

    F_active  = F0 f_L(l) f_V(v) cos α,     F_passive = F0 f_P(l) cos α.

Joint moments of a trial are therefore ``M[p, j] = Σ_m G[p, j, m] a[p, m] + M_passive[p, j]``
with the constant gains ``G = r · F_active`` computed once here.
"""

from __future__ import annotations

import attrs
import numpy as np

from nmsm.model import hill
from nmsm.tools.mtp.muscles import MuscleParameters
from nmsm.tools.ncp.inputs import NcpTrial


@attrs.frozen
class MomentGains:
    """``active`` (P, J, M) N·m per unit activation; ``passive`` (P, J) N·m."""

    active: np.ndarray
    passive: np.ndarray

    def moments(self, activations: np.ndarray) -> np.ndarray:
        """Joint moments (P, J) from activations (P, M) (numpy)."""
        return np.einsum("pjm,pm->pj", self.active, np.asarray(activations, dtype=float)) + self.passive


def normalized_fiber_kinematics(
    trial: NcpTrial, muscles: MuscleParameters, v_max_factor: float
) -> tuple[np.ndarray, np.ndarray]:
    """Normalized fiber length and velocity (P, M) of a trial (dimensionless)."""
    length = hill.normalized_fiber_length(
        trial.lengths, muscles.optimal_fiber_length, muscles.tendon_slack_length, muscles.pennation_angle
    )
    velocity = hill.normalized_fiber_velocity(
        trial.velocities, muscles.optimal_fiber_length, muscles.pennation_angle, v_max_factor
    )
    return np.asarray(length), np.asarray(velocity)


def moment_gains(trial: NcpTrial, muscles: MuscleParameters, v_max_factor: float,
                 curves: hill.MuscleCurves = hill.CURVES) -> MomentGains:
    """The activation-to-moment gains and passive moments of one trial (``curves``: the
    force-length-velocity curves' constants)."""
    length, velocity = normalized_fiber_kinematics(trial, muscles, v_max_factor)
    active_force = hill.active_tendon_force(
        1.0, length, velocity, muscles.max_isometric_force, muscles.pennation_angle, curves
    )  # (P, M)
    passive_force = hill.passive_tendon_force(length, muscles.max_isometric_force, muscles.pennation_angle, curves)
    active = trial.moment_arms * np.asarray(active_force)[:, None, :]
    passive = hill.joint_moments(trial.moment_arms, passive_force)
    return MomentGains(active=active, passive=passive)

"""MTP's modeled quantities as CasADi expressions, one trial at a time.

Chain per trial and muscle (docs/mtp.md, Meyer 2017):

1. excitation ``e_k = S(t_k - EMD/10)``, ``S`` the not-a-knot spline of the (scaled)
   EMG samples (:mod:`nmsm.tools.mtp.emg_spline`), ``t_k`` evenly spaced over the EMG time;
2. neural activation by BDF2 with ``tau_a = act/100`` s, padding frames dropped,
   negatives set to 0;
3. activation nonlinearity ``A``;
4. normalized fiber length/velocity with scaled ``l_o``, ``l_ts``; tendon force and passive
   force (:mod:`nmsm.model.hill`); joint moments ``sum_m r F``.

Two SX functions per trial are ``map``-ped over the muscles: excitation -> activation
(activation parameters; with SynX also synergy weights enter through the excitation
samples) and (activation, normalized length, normalized velocity) -> tendon force.
Normalized lengths, velocities and passive forces are plain MX elementwise expressions of
the length scale factors. A problem may *lift* activations, forces and moments (decision variables constrained to the modeled values,
:func:`nmsm.tools.mtp.problem.build_task_problem`) so that exact Jacobians and Hessians
stay sparse. Design quantities enter in their MTP units: electromechanical delay in
0.1 s, activation time constant in 0.01 s.

Shapes of :class:`TrialModel` fields: excitations ``(n_emg, n_muscles)``, the rest
``(n_frames, n_muscles)``, moments ``(n_frames, n_coordinates)``.
"""

from __future__ import annotations

from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.function_names import function_name
from nmsm.model import hill
from nmsm.tools.mtp import emg_spline
from nmsm.tools.mtp.data import TrialData
from nmsm.tools.mtp.muscles import MuscleParameters

#: upper bound of the electromechanical-delay variable (0.1 s): the spline pieces searched
MAX_DELAY_VARIABLE = 1.25


@attrs.frozen
class MuscleDesign:
    """Per-muscle design quantities (CasADi row vectors ``1 x n_muscles`` or numpy (n,)).

    ``electromechanical_delay`` in 0.1 s, ``activation_time_constant`` in 0.01 s,
    ``activation_nonlinearity`` (-), ``emg_scale`` (-), ``optimal_fiber_length_scale`` and
    ``tendon_slack_length_scale`` (-).
    """

    electromechanical_delay: Any
    activation_time_constant: Any
    activation_nonlinearity: Any
    emg_scale: Any
    optimal_fiber_length_scale: Any
    tendon_slack_length_scale: Any

    @staticmethod
    def initial(n_muscles: int) -> MuscleDesign:
        """The original's initial values (docs/mtp.md)."""
        return MuscleDesign(
            electromechanical_delay=np.full(n_muscles, 0.5),
            activation_time_constant=np.full(n_muscles, 1.5),
            activation_nonlinearity=np.full(n_muscles, 0.05),
            emg_scale=np.full(n_muscles, 0.5),
            optimal_fiber_length_scale=np.ones(n_muscles),
            tendon_slack_length_scale=np.ones(n_muscles),
        )


def row(value: Any, n: int) -> cs.MX:
    """A ``1 x n`` MX row from numpy (n,) or a CasADi vector/row."""
    if isinstance(value, (cs.MX, cs.SX, cs.DM)):
        v = value if isinstance(value, cs.MX) else cs.MX(value)
        return cs.reshape(v, 1, n)
    return cs.MX(cs.DM(np.asarray(value, dtype=float).reshape(1, n)))


@attrs.frozen(eq=False)
class TrialModel:
    """Modeled quantities of one trial (CasADi MX).

    ``activations``, ``tendon_force``, ``moments`` are what downstream quantities and
    costs use (lifted variables in an optimization); ``modeled_*`` are the model's values
    of the same quantities given their inputs.
    """

    name: str
    excitations: cs.MX
    excitations_undelayed: cs.MX
    neural_activations: cs.MX
    activations: cs.MX
    normalized_fiber_length: cs.MX
    normalized_fiber_velocity: cs.MX
    tendon_force: cs.MX
    passive_force: cs.MX
    moments: cs.MX
    modeled_activations: cs.MX
    modeled_moments: cs.MX
    modeled_tendon_force: cs.MX


class TrialChain:
    """Builds the per-muscle SX functions of one trial (sample times, spline pieces, padding).

    ``stride``: the EMG spline goes through every ``stride``-th EMG sample (the original's
    Synergy Extrapolation path uses 4; see :class:`nmsm.tools.mtp.problem.MtpData`).
    ``clip_smoothing``: half-width (-) of the smooth ramp replacing "negative neural
    activations set to 0" (:func:`nmsm.model.hill.clip_negative`); 0 = the original's hard clip.
    ``curves``: the force-length-velocity curves' constants (:class:`nmsm.model.hill.MuscleCurves`).
    """

    def __init__(
        self,
        trial: TrialData,
        *,
        stride: int = 4,
        clip_smoothing: float = 0.0,
        max_delay_variable: float = MAX_DELAY_VARIABLE,
        curves: hill.MuscleCurves = hill.CURVES,
    ) -> None:
        if trial.emg_time is None:
            raise ValueError(f"trial '{trial.name}' has no EMG")
        self.trial = trial
        self.stride = stride
        self.clip_smoothing = float(clip_smoothing)
        t = np.asarray(trial.emg_time, dtype=float)
        self.n_emg = t.size
        self.sample_times = (t[-1] - t[0]) * np.linspace(0.0, 1.0, t.size) + t[0]
        self.breaks = emg_spline.spline_breaks(t, stride)
        self.spline_matrix = emg_spline.spline_matrix(t, stride)  # (4 P, n_emg)
        self.dt = float(np.mean(np.diff(t)))
        self.padding = trial.padding
        self.max_delay = max_delay_variable / 10.0
        self.curves = curves
        self.activation_function, self.force_function = self._build()

    def _build(self) -> tuple[cs.Function, cs.Function]:
        n = self.trial.n_frames
        sampler = emg_spline.delayed_sampler(self.breaks, self.sample_times, self.max_delay, "emg_delay")
        dynamics = hill.neural_activation_function(self.n_emg)
        delay = cs.SX.sym("delay")  # 0.1 s
        tau = cs.SX.sym("tau")  # 0.01 s
        nonlin = cs.SX.sym("A")
        coefs = cs.SX.sym("coefs", self.spline_matrix.shape[0])
        e = sampler(delay / 10.0, coefs)
        neural_all = dynamics(e, tau / 100.0, self.dt)
        pad = self.padding
        neural = hill.clip_negative(neural_all[pad : pad + n], self.clip_smoothing)
        act = hill.activation_nonlinearity(neural, nonlin)
        activation = cs.Function(
            function_name("mtp_activation", self.trial.name),
            [delay, tau, nonlin, coefs],
            [e, neural, act],
            ["delay", "tau", "A", "coefs"],
            ["e", "n", "a"],
        )
        a = cs.SX.sym("a", n)
        lnorm = cs.SX.sym("l", n)
        vnorm = cs.SX.sym("v", n)
        alpha = cs.SX.sym("alpha")
        f0 = cs.SX.sym("F0")
        force = cs.Function(
            function_name("mtp_force", self.trial.name),
            [a, lnorm, vnorm, f0, alpha],
            [hill.tendon_force(a, lnorm, vnorm, f0, alpha, self.curves)],
            ["a", "l", "v", "F0", "alpha"],
            ["F"],
        )
        return activation, force

    def activations(self, design: MuscleDesign, excitation_samples: Any) -> tuple[cs.MX, cs.MX, cs.MX]:
        """``(excitations (n_emg, M), neural activations (n, M), activations (n, M))``."""
        m = int(excitation_samples.shape[1])
        coefs = cs.mtimes(cs.DM(self.spline_matrix), excitation_samples)
        e, neural, act = self.activation_function.map(m)(
            row(design.electromechanical_delay, m),
            row(design.activation_time_constant, m),
            row(design.activation_nonlinearity, m),
            coefs,
        )
        return e, neural, act

    def fiber_kinematics(self, muscles: MuscleParameters, design: MuscleDesign, vmax_factor: float) -> tuple[cs.MX, cs.MX]:
        """Normalized fiber lengths and velocities ``(n, M)`` as MX of the scale factors."""
        m = muscles.n_muscles
        n = self.trial.n_frames
        lo = cs.repmat(cs.DM(muscles.optimal_fiber_length.reshape(1, m)) * row(design.optimal_fiber_length_scale, m), n, 1)
        lts = cs.repmat(cs.DM(muscles.tendon_slack_length.reshape(1, m)) * row(design.tendon_slack_length_scale, m), n, 1)
        cos_alpha = cs.DM(np.repeat(np.cos(muscles.pennation_angle).reshape(1, m), n, axis=0))
        lnorm = (cs.DM(self.trial.muscle_tendon_length) - lts) / (lo * cos_alpha)
        vnorm = cs.DM(self.trial.muscle_tendon_velocity) / (float(vmax_factor) * lo * cos_alpha)
        return lnorm, vnorm

    def tendon_forces(self, muscles: MuscleParameters, activations: Any, lnorm: Any, vnorm: Any) -> cs.MX:
        """Tendon forces ``(n, M)`` (N)."""
        m = muscles.n_muscles
        return self.force_function.map(m)(
            activations,
            lnorm,
            vnorm,
            cs.DM(muscles.max_isometric_force.reshape(1, m)),
            cs.DM(muscles.pennation_angle.reshape(1, m)),
        )

    def passive_forces(self, muscles: MuscleParameters, lnorm: Any) -> cs.MX:
        """Passive tendon forces ``F0 f_P(l) cos alpha`` ``(n, M)`` (N), elementwise MX."""
        m = muscles.n_muscles
        n = self.trial.n_frames
        scale = cs.DM(np.repeat((muscles.max_isometric_force * np.cos(muscles.pennation_angle)).reshape(1, m), n, axis=0))
        return scale * hill.passive_force_length(lnorm)

    def evaluate(
        self,
        muscles: MuscleParameters,
        design: MuscleDesign,
        excitation_samples: Any,
        vmax_factor: float,
        *,
        lifted: dict[str, Any] | None = None,
    ) -> TrialModel:
        """Modeled quantities from undelayed excitation samples ``(n_emg, n_muscles)``.

        ``lifted``: optional ``activations``, ``forces``, ``moments`` (decision variables
        constrained elsewhere to the modeled values) used in place of the modeled ones
        downstream.
        """
        lifted = lifted or {}
        e, neural, act = self.activations(design, excitation_samples)
        lnorm, vnorm = self.fiber_kinematics(muscles, design, vmax_factor)
        a_used = lifted.get("activations", act)
        modeled_force = self.tendon_forces(muscles, a_used, lnorm, vnorm)
        force = lifted.get("forces", modeled_force)
        moments = joint_moments(self.trial.moment_arms, force)
        return TrialModel(
            name=self.trial.name,
            excitations=e,
            excitations_undelayed=cs.MX(excitation_samples),
            neural_activations=neural,
            activations=a_used,
            normalized_fiber_length=lnorm,
            normalized_fiber_velocity=vnorm,
            tendon_force=force,
            passive_force=self.passive_forces(muscles, lnorm),
            moments=lifted.get("moments", moments),
            modeled_activations=act,
            modeled_moments=moments,
            modeled_tendon_force=modeled_force,
        )


def joint_moments(moment_arms: np.ndarray, forces: Any) -> cs.MX:
    """``M[k, c] = sum_m r[k, c, m] F[k, m]`` (N m) for MX forces ``(n_frames, n_muscles)``."""
    cols = [cs.sum2(cs.DM(moment_arms[:, c, :]) * forces) for c in range(moment_arms.shape[1])]
    return cs.horzcat(*cols) if cols else cs.MX(forces.shape[0], 0)


def scaled_emg_samples(emg: np.ndarray, channel_of_muscle: np.ndarray, emg_scale: Any) -> cs.MX:
    """``s_emg * EMG`` expanded to muscles ``(n_emg, n_muscles)``; muscles without EMG get 0."""
    n_emg = emg.shape[0]
    m = channel_of_muscle.size
    expanded = expand_emg(emg, channel_of_muscle)
    return cs.DM(expanded) * cs.repmat(row(emg_scale, m), n_emg, 1)


def expand_emg(emg: np.ndarray, channel_of_muscle: np.ndarray) -> np.ndarray:
    """EMG channels ``(n_emg, n_channels)`` to muscles ``(n_emg, n_muscles)`` (0 without a channel)."""
    out = np.zeros((emg.shape[0], channel_of_muscle.size))
    has = channel_of_muscle >= 0
    out[:, has] = emg[:, channel_of_muscle[has]]
    return out


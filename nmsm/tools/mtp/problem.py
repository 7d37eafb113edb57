"""One MTP task as an :class:`~nmsm.core.problem.OptimizationProblem` (IPOPT).

Design-variable blocks (docs/mtp.md), one value per muscle, included by the task's
``optimize_*`` flags (excluded blocks stay at their current values):

====================================  =========  ======  ==============
block                                 unit       init    bounds
====================================  =========  ======  ==============
``electromechanical_delay``           0.1 s      0.5     [0, 1.25]
``activation_time_constant``          0.01 s     1.5     [0.75, 3.5]
``activation_nonlinearity``           -          0.05    [0, 0.35]
``emg_scale``                         -          0.5     [0.05, 1]
``optimal_fiber_length_scale``        -          1       [0.6, 1.4]
``tendon_slack_length_scale``         -          1       [0.6, 1.4]
``synergy_weights`` (SynX)            -          0       [-100, 100] (NMF: extrapolation >= 0)
====================================  =========  ======  ==============

Normalized fiber lengths stay in [0.3, 1.3]: by default every frame's (enforced at each
muscle's shortest and longest muscle-tendon length, see :func:`extreme_fiber_lengths`); the
original's per-muscle soft maximum over trials and frames (k = 500),
``log(sum(exp(k (l - 1.3)))) / k <= 0`` and ``log(sum(exp(k (0.3 - l)))) / k <= 0``, is
available (``fiber_length_limits="softmax"``). With SynX the extrapolated (unscaled)
excitations are bounded to [0, 1] (linear).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.term import CostTerm
from nmsm.core.threads import SOLVER_THREADS
from nmsm.tools.mtp.context import MtpContext
from nmsm.tools.mtp.data import TrialData
from nmsm.tools.mtp.derivatives import blockwise_derivatives
from nmsm.tools.mtp.model import MuscleDesign, TrialChain, TrialModel, expand_emg, scaled_emg_samples
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters
from nmsm.tools.mtp.synx import SynergyExtrapolation

#: block name -> (initial, lower, upper)
BLOCKS: dict[str, tuple[float, float, float]] = {
    "electromechanical_delay": (0.5, 0.0, 1.25),
    "activation_time_constant": (1.5, 0.75, 3.5),
    "activation_nonlinearity": (0.05, 0.0, 0.35),
    "emg_scale": (0.5, 0.05, 1.0),
    "optimal_fiber_length_scale": (1.0, 0.6, 1.4),
    "tendon_slack_length_scale": (1.0, 0.6, 1.4),
}
SYNERGY_WEIGHT_BOUNDS = (-100.0, 100.0)
#: half-width of the smooth ramp replacing "negative neural activations set to 0" (see
#: nmsm.model.hill.clip_negative): exact outside |x| < 0.01, at most 0.0019 above max(x, 0).
#: The original clips hard, which stalls IPOPT when synergy extrapolation drives excitations
#: below 0; a narrow smoothing (1e-4) leaves a near-kink of curvature ~1e4 that IPOPT crawls
#: through (docs/developing.md, "MTP: measurements and audit trail").
DEFAULT_CLIP_SMOOTHING = 1e-2
#: soft-maximum sharpness and limits of the normalized-fiber-length constraints
CONSTRAINT_SHARPNESS = 500.0
CONSTRAINT_MAX_LENGTH = 1.3
CONSTRAINT_MIN_LENGTH = 0.3

#: IPOPT's initial barrier parameter of :func:`solve_task_problem` (IPOPT's default 0.1, which
#: MTLI keeps); the measurements that chose it are in docs/mtp.md.
TASK_MU_INIT = 1e-3
#: MUMPS fill-reducing ordering of :func:`solve_task_problem` (IPOPT's ``mumps_pivot_order``:
#: 2 = approximate minimum fill): the same iterates as MUMPS's automatic choice, faster on the
#: larger problems (docs/mtp.md).
TASK_MUMPS_ORDERING = 2
#: threads of the block-wise Jacobian and Hessian evaluations of :func:`solve_task_problem`
#: (:func:`nmsm.tools.mtp.derivatives.parallel_sum`; :data:`nmsm.core.threads.SOLVER_THREADS`).
DERIVATIVE_THREADS = SOLVER_THREADS


@attrs.frozen(eq=False)
class MtpData:
    """Fixed inputs of MTP: muscles (base lengths), trials, channel map, groups, SynX.

    ``stride``: EMG splines through every ``stride``-th sample. The original splines every
    sample on its EMG-only path but every 4th on its SynX path; one stride for both keeps
    the two paths consistent (zero SynX residuals give identical activations) and makes
    the delayed spline cheaper. ``clip_smoothing``: see :data:`DEFAULT_CLIP_SMOOTHING`.
    """

    muscles: MuscleParameters
    coordinates: tuple[str, ...]
    trials: tuple[TrialData, ...]
    channel_of_muscle: np.ndarray
    activation_groups: tuple[MuscleGroup, ...] = ()
    fiber_length_groups: tuple[MuscleGroup, ...] = ()
    synx: SynergyExtrapolation | None = None
    vmax_factor: float = 10.0
    stride: int = 4
    clip_smoothing: float = DEFAULT_CLIP_SMOOTHING

    @property
    def missing(self) -> tuple[int, ...]:
        return tuple(int(i) for i in np.flatnonzero(self.channel_of_muscle < 0))

    @property
    def measured(self) -> tuple[int, ...]:
        return tuple(int(i) for i in np.flatnonzero(self.channel_of_muscle >= 0))

    @property
    def padding(self) -> int:
        return self.trials[0].padding

    def chains(self) -> list[TrialChain]:
        return [TrialChain(t, stride=self.stride, clip_smoothing=self.clip_smoothing) for t in self.trials]

    def expanded_emg(self) -> list[np.ndarray]:
        assert all(t.emg is not None for t in self.trials)
        return [expand_emg(t.emg, self.channel_of_muscle) for t in self.trials]


@attrs.define
class MtpState:
    """Current values (numpy) of every block: per-muscle arrays (n,) and SynX weights."""

    design: MuscleDesign
    synergy_weights: np.ndarray = attrs.field(factory=lambda: np.zeros(0))

    @staticmethod
    def initial(data: MtpData) -> MtpState:
        n_weights = data.synx.n_weights if data.synx is not None else 0
        return MtpState(MuscleDesign.initial(data.muscles.n_muscles), np.zeros(n_weights))


@attrs.frozen
class TaskSettings:
    """What one task optimizes and how it is scored."""

    optimize: dict[str, bool] = attrs.field(factory=lambda: dict.fromkeys(BLOCKS, True))
    cost_terms: tuple[CostTerm, ...] = ()
    synx_terms: tuple[CostTerm, ...] = ()
    min_normalized_fiber_length: float = 0.75
    max_normalized_fiber_length: float = 1.05


def modeled_trials(
    data: MtpData,
    design: MuscleDesign,
    synergy_weights: Any,
    chains: Sequence[TrialChain] | None = None,
    *,
    lifted: Sequence[dict[str, Any]] | None = None,
    lifted_synx: Sequence[dict[str, Any]] | None = None,
) -> tuple[list[TrialModel], list[TrialModel] | None]:
    """Modeled quantities of every trial without and (if enabled) with SynX.

    ``lifted`` / ``lifted_synx``: per trial, decision variables replacing modeled
    quantities downstream (see :meth:`TrialChain.evaluate`).
    """
    chains = list(chains) if chains is not None else data.chains()
    plain = []
    for k, (chain, trial) in enumerate(zip(chains, data.trials)):
        x = scaled_emg_samples(trial.emg, data.channel_of_muscle, design.emg_scale)
        plain.append(chain.evaluate(data.muscles, design, x, data.vmax_factor, lifted=None if lifted is None else lifted[k]))
    synx_models = None
    if data.synx is not None:
        samples = data.synx.excitation_samples(data.expanded_emg(), design.emg_scale, synergy_weights)
        synx_models = [
            c.evaluate(data.muscles, design, x, data.vmax_factor, lifted=None if lifted_synx is None else lifted_synx[k])
            for k, (c, x) in enumerate(zip(chains, samples))
        ]
    return plain, synx_models


def fiber_length_constraints(models: Sequence[TrialModel]) -> tuple[cs.MX, cs.MX]:
    """Per-muscle soft maxima of ``l - 1.3`` and ``0.3 - l`` (each ``(n_muscles, 1)``, must be <= 0)."""
    k = CONSTRAINT_SHARPNESS
    stacked = cs.vertcat(*[m.normalized_fiber_length for m in models])
    upper = [cs.logsumexp(k * (stacked[:, i] - CONSTRAINT_MAX_LENGTH)) / k for i in range(stacked.shape[1])]
    lower = [cs.logsumexp(k * (CONSTRAINT_MIN_LENGTH - stacked[:, i])) / k for i in range(stacked.shape[1])]
    return cs.vertcat(*upper), cs.vertcat(*lower)


def extreme_fiber_lengths(models: Sequence[TrialModel], trials: Sequence[TrialData]) -> tuple[cs.MX, cs.MX]:
    """Each muscle's normalized fiber length at its shortest and longest muscle-tendon
    length over all trials and frames (each ``(n_muscles, 1)``).

    With a rigid tendon and constant pennation ``l = (l_MT - l_ts) / (l_o cos alpha)``
    increases with ``l_MT`` for every design (``l_o > 0``), so bounding these two values is
    the same as bounding every frame's value: two rows per muscle instead of one per frame
    and muscle in IPOPT's linear systems.
    """
    lengths = np.vstack([np.asarray(t.muscle_tendon_length, dtype=float) for t in trials])
    owner = np.concatenate([np.full(t.n_frames, k) for k, t in enumerate(trials)])
    frame = np.concatenate([np.arange(t.n_frames) for t in trials])
    picks = []
    for rows in (np.argmin(lengths, axis=0), np.argmax(lengths, axis=0)):
        picks.append(cs.vertcat(*[models[owner[r]].normalized_fiber_length[int(frame[r]), i]
                                  for i, r in enumerate(rows)]))
    return picks[0], picks[1]


def _warn_fixed_lengths_outside(models: Sequence[TrialModel], muscles: Sequence[str], name: str) -> None:
    """Warn, naming the muscles, when fixed optimal fiber and tendon slack lengths put a
    normalized fiber length outside [0.3, 1.3] (the limits are then left out of the task)."""
    stacked = np.vstack([np.asarray(cs.evalf(m.normalized_fiber_length)) for m in models])
    low, high = stacked.min(axis=0), stacked.max(axis=0)
    outside = [f"{muscles[i]} ({low[i]:.2f}..{high[i]:.2f})" for i in range(len(muscles))
               if low[i] < CONSTRAINT_MIN_LENGTH or high[i] > CONSTRAINT_MAX_LENGTH]
    if outside:
        warnings.warn(
            f"{name}: optimal fiber and tendon slack lengths are not optimized in this task and put "
            f"normalized fiber lengths outside [{CONSTRAINT_MIN_LENGTH}, {CONSTRAINT_MAX_LENGTH}]: "
            + ", ".join(outside) + "; the limits apply from the first task that optimizes those lengths",
            stacklevel=3,
        )


def build_task_problem(
    data: MtpData,
    state: MtpState,
    task: TaskSettings,
    initial_fiber_length: Sequence[np.ndarray],
    *,
    chains: Sequence[TrialChain] | None = None,
    name: str = "MTP task",
    lift: bool = True,
    fiber_length_limits: str = "frames",
) -> tuple[OptimizationProblem, MtpContext]:
    """The task's problem (variables, terms, constraints) and the terms' context.

    ``lift``: activations, tendon forces and moments become decision variables
    (``activations_<trial>``, ``tendon_forces_<trial>``, ``moments_<trial>``, with SynX also
    ``synx_...``) with equality constraints to the
    modeled ones. The solution is the same; exact Jacobians and Hessians stay sparse (the
    moments couple all muscles only through the linear sum of forces), which makes IPOPT
    with exact second derivatives fast.

    ``fiber_length_limits``: ``"frames"`` bounds every normalized fiber length to
    [0.3, 1.3] (smooth, well conditioned); ``"softmax"`` is the original's per-muscle soft
    maximum with sharpness 500 (stricter by at most ``log(n_trials n_frames) / 500``), whose
    gradients grow 500-fold near the limit and stall IPOPT on patient data. A task that
    optimizes neither l_o nor l_ts gets no limits (they would be constants): it warns,
    naming the muscles, when those constants are outside [0.3, 1.3].
    """
    problem = OptimizationProblem(name)
    m = data.muscles.n_muscles
    values: dict[str, Any] = {}
    for block, (_, lower, upper) in BLOCKS.items():
        current = np.asarray(getattr(state.design, block), dtype=float)
        if task.optimize.get(block, True):
            values[block] = cs.reshape(problem.variable(block, np.clip(current, lower, upper), lower, upper), 1, m)
        else:
            values[block] = cs.MX(cs.DM(current.reshape(1, m)))
    design = MuscleDesign(**values)
    weights: Any = cs.MX(0, 1)
    if data.synx is not None:
        low, high = data.synx.weight_bounds(*SYNERGY_WEIGHT_BOUNDS)
        # scale 1: typical weights are O(0.1-1), far below the +-100 bounds
        weights = problem.variable("synergy_weights", np.clip(state.synergy_weights, low, high), low, high, scale=1.0)
    chains = list(chains) if chains is not None else data.chains()
    lifted = lifted_synx = None
    if lift:
        lifted, lifted_synx = _lift(problem, data, state, chains)
    plain, synx_models = modeled_trials(data, design, weights, chains, lifted=lifted, lifted_synx=lifted_synx)
    if lift:
        _lifting_constraints(problem, plain, lifted, "")
        if synx_models is not None:
            _lifting_constraints(problem, synx_models, lifted_synx, "synx_")
    ctx = MtpContext(
        muscles=data.muscles,
        design=design,
        models=plain,
        synx_models=synx_models,
        inverse_dynamics_moments=[t.inverse_dynamics_moments for t in data.trials],
        initial_fiber_length=list(initial_fiber_length),
        activation_groups=data.activation_groups,
        fiber_length_groups=data.fiber_length_groups,
        measured=data.measured,
        missing=data.missing,
        padding=data.padding,
        min_normalized_fiber_length=task.min_normalized_fiber_length,
        max_normalized_fiber_length=task.max_normalized_fiber_length,
    )
    for term in task.cost_terms:
        problem.add_term(term, ctx)
    if data.synx is not None:
        for term in task.synx_terms:
            problem.add_term(term, ctx)
    lengths_fixed = not (task.optimize.get("optimal_fiber_length_scale", True)
                         or task.optimize.get("tendon_slack_length_scale", True))
    if lengths_fixed:
        # the limits depend on l_o and l_ts only: with both fixed they are constants that no
        # design variable can change (IPOPT would only report an infeasible problem)
        _warn_fixed_lengths_outside(plain, data.muscles.names, name)
    elif fiber_length_limits == "softmax":
        upper, lower = fiber_length_constraints(plain)
        problem.add_constraint("normalized_fiber_length_max_1.3", upper, -np.inf, 0.0)
        problem.add_constraint("normalized_fiber_length_min_0.3", lower, -np.inf, 0.0)
    elif fiber_length_limits == "frames":
        shortest, longest = extreme_fiber_lengths(plain, data.trials)
        problem.add_constraint("normalized_fiber_length_min_0.3", shortest, CONSTRAINT_MIN_LENGTH, np.inf)
        problem.add_constraint("normalized_fiber_length_max_1.3", longest, -np.inf, CONSTRAINT_MAX_LENGTH)
    else:
        raise ValueError(f"fiber_length_limits must be 'frames' or 'softmax', got '{fiber_length_limits}'")
    if data.synx is not None and data.synx.missing_muscles:
        problem.add_constraint("extrapolated_excitation_0_1", data.synx.extrapolated_bounds_expression(weights), 0.0, 1.0)
    return problem, ctx


def solve_task_problem(problem: OptimizationProblem, *, max_iterations: int, tolerance: float = 1e-6,
                       print_level: int = 0) -> Solution:
    """Solve an MTP task problem as ``nmsm run`` does: IPOPT with block-wise exact
    derivatives (:func:`nmsm.tools.mtp.derivatives.blockwise_derivatives`) and
    ``mu_init`` = :data:`TASK_MU_INIT` and MUMPS ordering :data:`TASK_MUMPS_ORDERING`;
    the derivative blocks on :data:`DERIVATIVE_THREADS` threads."""
    return problem.solve(
        "ipopt",
        max_iter=int(max_iterations),
        tol=float(tolerance),
        print_level=print_level,
        ipopt_options={"mu_init": TASK_MU_INIT, "mumps_pivot_order": TASK_MUMPS_ORDERING},
        casadi_options=blockwise_derivatives(problem, threads=DERIVATIVE_THREADS),
    )


def _lift(
    problem: OptimizationProblem, data: MtpData, state: MtpState, chains: Sequence[TrialChain]
) -> tuple[list[dict[str, Any]], list[dict[str, Any]] | None]:
    """Lifted variables per trial (activations, tendon forces, moments) at ``state``'s values.

    Every lifting equality then depends on one muscle's parameters (activations: through
    the activation dynamics of one muscle; forces: one frame's activation and the muscle's
    length scales) or on one frame's forces (moments, linear): exact Jacobians and Hessians
    need few colours (see :mod:`nmsm.tools.mtp.derivatives`), and the activation cost terms
    become quadratic in variables. Forces are scaled by each muscle's ``F0 cos(alpha)`` and
    moments by each coordinate's largest ID moment, variables and equality rows alike, so
    all lifted quantities are O(1). (What lifting saves is measured in docs/developing.md,
    "MTP: measurements and audit trail".)
    """
    design = MuscleDesign(**{f: np.asarray(getattr(state.design, f), dtype=float) for f in BLOCKS})
    plain, synx = modeled_trials(data, design, cs.DM(np.asarray(state.synergy_weights, dtype=float)), chains)
    fields = ("activations", "tendon_force", "moments")
    models = plain + (synx or [])
    values = cs.Function("lift_start", [], [getattr(m, f) for m in models for f in fields]).call([])
    force_scale = (data.muscles.max_isometric_force * np.cos(data.muscles.pennation_angle)).reshape(1, -1)
    out: list[dict[str, Any]] = []
    for i, model in enumerate(models):
        act, force, mom = (np.array(values[i * len(fields) + j].full()) for j in range(len(fields)))
        prefix = "" if i < len(plain) else "synx_"
        trial = data.trials[i % len(plain)]
        moment_scale = np.maximum(np.abs(trial.inverse_dynamics_moments).max(axis=0), 1.0).reshape(1, -1)
        out.append({
            "activations": problem.variable(f"{prefix}activations_{model.name}", act, scale=1.0),
            "forces": problem.variable(f"{prefix}tendon_forces_{model.name}", force, scale=force_scale),
            "moments": problem.variable(f"{prefix}moments_{model.name}", mom, scale=moment_scale),
            "force_scale": force_scale,
            "moment_scale": moment_scale,
        })
    return out[: len(plain)], (out[len(plain) :] if synx is not None else None)


def _lifting_constraints(problem: OptimizationProblem, models: Sequence[TrialModel],
                         lifted: Sequence[dict[str, Any]], prefix: str) -> None:
    """Equalities tying lifted variables to the modeled quantities (rows scaled to O(1))."""
    for model, values in zip(models, lifted):
        name = model.name
        n = int(model.activations.shape[0])
        force_rows = cs.DM(np.repeat(1.0 / values["force_scale"], n, axis=0))
        moment_rows = cs.DM(np.repeat(1.0 / values["moment_scale"], n, axis=0))
        problem.add_constraint(f"lifted_{prefix}activations_{name}",
                               values["activations"] - model.modeled_activations, 0.0, 0.0)
        problem.add_constraint(f"lifted_{prefix}forces_{name}",
                               (values["forces"] - model.modeled_tendon_force) * force_rows, 0.0, 0.0)
        problem.add_constraint(f"lifted_{prefix}moments_{name}",
                               (values["moments"] - model.modeled_moments) * moment_rows, 0.0, 0.0)


def updated_state(state: MtpState, values: dict[str, np.ndarray]) -> MtpState:
    """State with the solved blocks replaced."""
    design = attrs.evolve(
        state.design,
        **{k: np.asarray(v, dtype=float).ravel() for k, v in values.items() if k in BLOCKS},
    )
    weights = np.asarray(values["synergy_weights"], dtype=float).ravel() if "synergy_weights" in values else state.synergy_weights
    return MtpState(design, weights)


def absorb_length_scales(data: MtpData, state: MtpState) -> tuple[MtpData, MtpState]:
    """After a task: base lengths take the scale factors, which reset to 1 (as the original)."""
    d = state.design
    muscles = data.muscles.with_lengths(
        data.muscles.optimal_fiber_length * np.asarray(d.optimal_fiber_length_scale, dtype=float),
        data.muscles.tendon_slack_length * np.asarray(d.tendon_slack_length_scale, dtype=float),
    )
    n = muscles.n_muscles
    design = attrs.evolve(d, optimal_fiber_length_scale=np.ones(n), tendon_slack_length_scale=np.ones(n))
    return attrs.evolve(data, muscles=muscles), MtpState(design, state.synergy_weights)

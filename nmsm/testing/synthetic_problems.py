"""Small problems of the personalization tools (MTP, SynX, MTLI, NCP, GCP, JMP) for checking
their terms (:func:`nmsm.testing.check_term`), generated in code from known answers.

Each builder returns the tool's own problem and context (the tool's reduction), to which
:meth:`SyntheticProblem.add_term` adds the term under check as the tool does, and a
``tracked`` point where the synthetic data are reproduced exactly, so a tracking term is
zero there:

=========  ======================================================================================
tool       problem
=========  ======================================================================================
MTP, SynX  3 muscles crossing 3 coordinates, one trial of 101 frames (:mod:`nmsm.examples.synthetic_mtp`);
           muscle ``muscle_2`` has no EMG (Synergy Extrapolation, PCA, one synergy); activation group
           (``muscle_0``, ``muscle_1``), fiber-length group (``muscle_1``, ``muscle_2``). Tracked: the
           true parameters, synergy weights 0; inverse-dynamics moments are the model's there.
MTLI       the same muscles: one gait trial and one passive trial (muscle-tendon lengths 3 % longer)
           whose passive moments are the model's at unit scale factors (the tracked point).
NCP        two synergy groups ``right`` (``a_r``, ``b_r``, ``c_r``) and ``left`` (``b_l``, ``a_l``,
           ``c_l``), two synergies each, one coordinate, 15 frames; MTP activations for ``a_r`` and
           ``a_l``. Tracked: the initial guess, whose moments and activations are the data.
GCP        one right foot (:mod:`nmsm.examples.synthetic_gcp`, a 3 x 4 spring grid), every design
           block optimized; no tracked point (the foot kinematics are a B-spline fit of the data).
JMP        the synthetic leg (:mod:`nmsm.examples.synthetic_jmp`), 3 frames; the markers are the
           model's at the tracked coordinates and parameters.
=========  ======================================================================================

Files the GCP and JMP readers need (model, motion, forces) are written once per process into
a temporary folder removed at exit.
"""

from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem
from nmsm.core.term import CostTerm, Term


@attrs.define(eq=False)
class SyntheticProblem:
    """A tool's problem, ready for the term under check.

    ``tracked``: scaled variables (``problem.initial_scaled()`` order) where the synthetic data
    are reproduced exactly, or None where the problem has no such point. ``add``: adds a bound
    term to the problem as the tool does (default ``problem.add_term(term, context)``).
    ``form_problem``: what is wrong with a term's raw quantity for this tool's reduction (None
    if nothing), for tools whose reduction expects a form (GCP: one block per foot).
    """

    problem: OptimizationProblem
    context: Any
    tracked: np.ndarray | None
    add: Callable[[Term], None] | None = None
    form_problem: Callable[[Term], str | None] | None = None

    def add_term(self, term: Term) -> None:
        if self.add is not None:
            self.add(term)
        else:
            self.problem.add_term(term, self.context)


@functools.cache
def _folder() -> Path:
    path = Path(tempfile.mkdtemp(prefix="nmsm_check_term_"))
    atexit.register(shutil.rmtree, path, ignore_errors=True)
    return path


# ----------------------------------------------------------------------------- MTP, SynX
@functools.cache
def _mtp_case() -> tuple[Any, Any]:
    """(MtpData with SynX, the true MtpState) of the module docstring."""
    from nmsm.examples.synthetic_mtp import make_synthetic_mtp
    from nmsm.tools.mtp import synx
    from nmsm.tools.mtp.evaluation import evaluate
    from nmsm.tools.mtp.muscles import MuscleGroup
    from nmsm.tools.mtp.problem import MtpState

    case = make_synthetic_mtp(n_muscles=3, n_trials=1, seed=3)
    data = case.data
    emg = [t.emg[:, :2] for t in data.trials]
    extrapolation = synx.build_synergy_extrapolation(
        emg, [t.name for t in data.trials], method="PCA", n_synergies=1, extrapolation_categorization="subject",
        residual_categorization="trial", missing_muscles=[(2,)], channel_muscles=[(0,), (1,)])
    data = attrs.evolve(data, channel_of_muscle=np.array([0, 1, -1]), synx=extrapolation,
                        trials=tuple(attrs.evolve(t, emg=t.emg[:, :2]) for t in data.trials),
                        activation_groups=(MuscleGroup("activation_group", (0, 1)),),
                        fiber_length_groups=(MuscleGroup("fiber_length_group", (1, 2)),))
    truth = MtpState(case.truth.design, np.zeros(extrapolation.n_weights))
    plain, _ = evaluate(data, truth)
    trials = tuple(attrs.evolve(t, inverse_dynamics_moments=plain.moments[k]) for k, t in enumerate(data.trials))
    return attrs.evolve(data, trials=trials), truth


def mtp_problem(tool: str) -> SyntheticProblem:
    """The MTP task; its context serves the MTP and the Synergy Extrapolation (SynX) terms."""
    from nmsm.tools.mtp.evaluation import initial_fiber_lengths
    from nmsm.tools.mtp.problem import TaskSettings, build_task_problem

    data, truth = _mtp_case()
    problem, ctx = build_task_problem(data, truth, TaskSettings(), initial_fiber_lengths(data), name="check_term MTP")
    return SyntheticProblem(problem, ctx, problem.initial_scaled())


# ----------------------------------------------------------------------------------- MTLI
def mtli_problem(tool: str) -> SyntheticProblem:
    """The MTLI problem of the module docstring (scale factors, stress scale optimized)."""
    from nmsm.tools.mtp.mtli import MtliOptions, build_mtli_problem
    from nmsm.tools.mtp.mtli_model import PassiveTrial, mtli_quantities

    data, _ = _mtp_case()
    muscles, trial = data.muscles, data.trials[0]
    m = muscles.n_muscles
    options = MtliOptions(optimize_maximum_muscle_stress=True)
    passive = PassiveTrial("passive", trial.time, trial.muscle_tendon_length * 1.03, trial.moment_arms,
                           np.zeros(trial.moment_arms.shape[:2]))
    ones = cs.DM.ones(1, m)
    *_, moments = mtli_quantities(muscles, [trial.muscle_tendon_length], [passive], optimal_fiber_length=ones,
                                  tendon_slack_length=ones, stress_scale=1.0, absolute_lengths=False,
                                  update_max_isometric_force=options.update_max_isometric_force,
                                  maximum_muscle_stress=options.maximum_muscle_stress)
    passive = attrs.evolve(passive, inverse_dynamics_moments=np.array(cs.evalf(moments[0])))
    problem, ctx = build_mtli_problem(muscles, [trial.muscle_tendon_length], [passive], data.fiber_length_groups,
                                      [], options)
    return SyntheticProblem(problem, ctx, problem.initial_scaled())


# ------------------------------------------------------------------------------------ NCP
@functools.cache
def _ncp_case() -> tuple[Any, Any]:
    """(NcpInputs, SynergyGuess) of the module docstring."""
    from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters
    from nmsm.tools.ncp.forces import moment_gains
    from nmsm.tools.ncp.initial_guess import SynergyGuess
    from nmsm.tools.ncp.inputs import NcpInputs, NcpTrial
    from nmsm.tools.ncp.synergies import SynergyGroup, SynergyLayout, activations

    layout = SynergyLayout([SynergyGroup("right", ["a_r", "b_r", "c_r"], 2),
                            SynergyGroup("left", ["b_l", "a_l", "c_l"], 2)], n_nodes=6)
    names = list(layout.muscles)
    muscles = MuscleParameters(names, [1000.0, 800.0, 600.0, 800.0, 1000.0, 600.0],
                               [0.10, 0.08, 0.12, 0.08, 0.10, 0.12], [0.25, 0.30, 0.20, 0.30, 0.25, 0.20],
                               [0.0, 0.2, 0.1, 0.2, 0.0, 0.1])
    rng = np.random.default_rng(7)
    p = 15
    time = np.linspace(0.0, 0.7, p)
    base = muscles.tendon_slack_length + muscles.optimal_fiber_length * np.cos(muscles.pennation_angle)
    swing = 0.01 * np.sin(2 * np.pi * time[:, None] / 0.7 + rng.uniform(0, 2 * np.pi, len(names)))
    lengths = base[None, :] + swing
    velocities = np.gradient(lengths, time, axis=0)
    arms = np.tile(np.array([0.04, -0.03, 0.02, -0.03, 0.04, 0.02])[None, None, :], (p, 1, 1))
    trial = NcpTrial("trial", time, lengths, velocities, arms, np.zeros((p, 1)), np.zeros((p, 2)), ("q_moment",))
    inputs = NcpInputs(layout=layout, coordinates=["q"], trials=[trial], muscles=muscles, mtp_muscles=("a_r", "a_l"),
                       activation_groups=[MuscleGroup("activation_group", (0, 1, 2))],
                       fiber_length_groups=[MuscleGroup("fiber_length_group", (3, 4))])
    blocks = tuple(rng.uniform(0.2, 0.8, (2, 3)) for _ in layout.free_groups)
    guess = SynergyGuess(blocks, (rng.uniform(0.1, 0.5, (layout.n_nodes, layout.n_synergies)),))
    a = activations(layout.weight_matrix(list(blocks)), layout.commands(guess.nodes[0], p))
    moments = moment_gains(trial, muscles, inputs.v_max_factor, inputs.curves).moments(a)
    mtp = a[:, list(inputs.mtp_indices)]
    trial = attrs.evolve(trial, moments=moments, mtp_activations=mtp)
    return attrs.evolve(inputs, trials=(trial,)), guess


def ncp_problem(tool: str) -> SyntheticProblem:
    """The NCP problem of the module docstring (no proximal term)."""
    from nmsm.tools.ncp.problem import build_problem

    inputs, guess = _ncp_case()
    built = build_problem(inputs, [], guess, name="check_term NCP", proximal_weight=0.0)
    return SyntheticProblem(built.problem, built.context, built.problem.initial_scaled())


# ------------------------------------------------------------------------------------ GCP
@functools.cache
def _gcp_case() -> tuple[Any, list[Any], Any]:
    """(settings, feet, task with every design block optimized)."""
    from nmsm.examples.synthetic_gcp import write_synthetic_gcp
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.tools.gcp.run import load_feet

    case = write_synthetic_gcp(_folder() / "gcp", grid=(3, 4))
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(case.settings_file))
    feet = load_feet(settings)[0]
    flags = dict.fromkeys(settings.tasks[0].design_flags, True)
    return settings, feet, attrs.evolve(settings.tasks[0], **flags)


def gcp_problem(tool: str) -> SyntheticProblem:
    """The GCP task of the module docstring (foot coordinates not lifted)."""
    from nmsm.tools.gcp.problem import build_task_problem
    from nmsm.tools.gcp.state import GcpState

    settings, feet, task = _gcp_case()
    state = GcpState.initial(settings, feet)
    state.spring_constants = np.linspace(2000.0, 3000.0, state.spring_constants.size)  # not all equal
    built = build_task_problem(feet, state, task, [], name="check_term GCP", lift=False)

    def form_problem(term: Term) -> str | None:
        if not isinstance(term, CostTerm):
            return None
        blocks = term.normalized(built.context)
        if isinstance(blocks, (tuple, list)) and len(blocks) == len(feet):
            return None
        got = f"a {type(blocks).__name__}" + (f" of {len(blocks)}" if isinstance(blocks, (tuple, list)) else "")
        return f"quantity must be a tuple with one block per foot ({len(feet)} here), got {got}"

    return SyntheticProblem(built.problem, built.context, None, form_problem=form_problem)


# ------------------------------------------------------------------------------------ JMP
@functools.cache
def _jmp_case() -> tuple[Any, Any]:
    """(MarkerKinematics, JmpDesign) of the synthetic leg."""
    from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case
    from nmsm.io.trc import read_trc
    from nmsm.model import load_model
    from nmsm.tools.jmp.design import build_design
    from nmsm.tools.jmp.marker_model import MarkerKinematics
    from nmsm.tools.jmp.run import read_settings

    case = make_synthetic_jmp_case(_folder() / "jmp", noise=0.0, duration=0.03)
    settings = read_settings(case.settings_file)
    task = settings.tasks[0]
    model = load_model(settings.input_model_file)
    table = read_trc(task.marker_file_name)
    design = build_design(model, task, table.names)
    return MarkerKinematics(model, design.marker_names, design.parameters), design


def jmp_problem(tool: str, n_frames: int = 3) -> SyntheticProblem:
    """JMP's simultaneous problem (every frame's free coordinates and the joint parameters),
    a term's residuals frame after frame as JMP's own solver maps them."""
    from nmsm.tools.jmp.problem import JmpContext

    kin, design = _jmp_case()
    n_markers = kin.n_markers
    ctx = JmpContext(kin, cs.SX.sym("x_exp", 3 * n_markers), cs.SX.sym("sqrt_w", n_markers), n_markers * n_frames)
    rng = np.random.default_rng(3)
    q = kin.initial_free()[None, :] + 0.1 * rng.standard_normal((n_frames, kin.n_free))
    q = np.clip(q, kin.lower + 0.01, kin.upper - 0.01)
    p = design.initial
    x_exp = kin.marker_positions(q, p).reshape(n_frames, -1)  # (F, 3M), xyz per marker
    problem = OptimizationProblem("check_term JMP")
    q_var = problem.variable("q", q.T, np.tile(kin.lower[:, None], (1, n_frames)),
                             np.tile(kin.upper[:, None], (1, n_frames)), scale=1.0, shape=(kin.n_free, n_frames))
    p_var = problem.variable("p", p, design.lower, design.upper, scale=1.0)
    x_par = problem.parameter("x_exp", x_exp.T)
    w_par = problem.parameter("sqrt_w", np.ones((n_markers, n_frames)))

    def add(term: Term) -> None:
        term.bind(ctx)
        if isinstance(term, CostTerm):
            residuals, lower, upper = term.residuals(ctx), None, None
        else:
            residuals, lower, upper = term.bounded(ctx)
        frame = cs.Function("frame", [kin.q, kin.p, ctx.x_exp, ctx.sqrt_w], [cs.SX(residuals)])
        stacked = frame.map(n_frames)(q_var, p_var, x_par, w_par)
        if lower is None:
            problem.add_cost(term.label, stacked, term=term)
        else:
            problem.add_constraint(term.label, stacked, lower, upper, term=term)

    return SyntheticProblem(problem, ctx, problem.initial_scaled(), add=add)


#: tool -> builder of its synthetic problem
BUILDERS: dict[str, Callable[[str], SyntheticProblem]] = {
    "MTP": mtp_problem,
    "SynX": mtp_problem,
    "MTLI": mtli_problem,
    "NCP": ncp_problem,
    "GCP": gcp_problem,
    "JMP": jmp_problem,
}

#: Built-in tracking terms (tool, type) that are zero on each problem's ``tracked`` point.
ZERO_AT_TRACKED: frozenset[tuple[str, str]] = frozenset({
    ("MTP", "inverse_dynamics_joint_moment"),
    ("SynX", "measured_inverse_dynamics_joint_moment"),
    ("MTLI", "passive_joint_moment"),
    ("NCP", "moment_tracking"),
    ("NCP", "activation_tracking"),
    ("JMP", "marker_distance_error"),
})


__all__ = ["BUILDERS", "SyntheticProblem", "ZERO_AT_TRACKED", "gcp_problem", "jmp_problem",
           "mtli_problem", "mtp_problem", "ncp_problem"]

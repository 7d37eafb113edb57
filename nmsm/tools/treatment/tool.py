"""Tracking (TO), Verification (VO) and Design Optimization (DO): settings -> problem -> results.

:func:`prepare` reads the settings' files and builds the problem; :func:`solve` runs IPOPT
(saving the last iterate and a diagnosis, then raising :class:`SolverError`, when it fails);
:mod:`nmsm.tools.treatment.outputs` writes the results. ``run_settings`` in
:mod:`nmsm.tools.treatment.run` chains them.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.registry import get_registry
from nmsm.core.term import Term
from nmsm.core.registry import build_terms
from nmsm.core.threads import SOLVER_THREADS
from nmsm.errors import InputError
from nmsm.core.bounds import RangeRule, check_guess_within, range_bounds
from nmsm.core.controller_setup import ControllerSetup
from nmsm.tools.treatment.formulation import StateSetup, TreatmentProblem, build_problem, speed_label
from nmsm.tools.treatment.inputs import TreatmentFiles, duration, guess_time_problems, read_treatment_files
from nmsm.tools.treatment.memory import MemoryEstimate, check_memory
from nmsm.core.ocp_model import TreatmentModel
from nmsm.tools.treatment.problem_data import TreatmentData
from nmsm.core.splines import ReferenceSplines
from nmsm.tools.treatment.solver_options import DESIGN_MAX_TOLERANCE, MAX_TOLERANCE, SolverPlan, plan_from_settings
from nmsm.tools.treatment.term_defaults import default_error_warnings

#: settings attribute of each controller element, in the order controls are laid out
CONTROLLER_ELEMENTS = (("RCNLSynergyController", "synergy_controller"), ("RCNLMuscleController", "muscle_controller"),
                       ("RCNLTorqueController", "torque_controller"))


#: threads of the per-point model functions (CasADi ``map`` with ``thread``
#: parallelization; :data:`nmsm.core.threads.SOLVER_THREADS`): the same iterates as one thread
#: (timings: docs/treatment.md).
DEFAULT_PARALLEL = SOLVER_THREADS


@attrs.define
class TreatmentOptions:
    """Run-time options of :func:`nmsm.tools.treatment.run.run_settings` (all optional).

    Directories override the settings file's (``guess_directory`` replaces only the
    starting point: references such as the initial controls of ``controller_tracking``
    still come from ``initial_guess_directory``). IPOPT: ``max_iterations``,
    ``tolerance``, ``hessian`` ('exact' or 'limited-memory'; default: the solver settings'
    ``<hessian_approximation>``, exact unless set), ``linear_solver``,
    ``print_level``, ``ipopt_options`` (any other IPOPT option), ``objective_scaling``
    ('initial': IPOPT minimizes the objective divided by its value at the initial guess,
    clipped to [1e-6, 1e6], so ``setup_nlp_tolerance`` acts on a relative scale; 'none';
    or a number: IPOPT's ``obj_scaling_factor``). ``parallel``: threads for
    the per-point model functions (default :data:`DEFAULT_PARALLEL`). ``rescale_prescribed_derivatives``: with a free final time,
    scale the prescribed coordinates' speeds and accelerations to the new duration (default;
    False reproduces the original, which keeps the data's speeds). ``warm_start``: start IPOPT
    with a small barrier parameter and bound push (mu_init 1e-6, bound_push/frac 1e-9) so it
    stays at a starting point that is already a solution; default (None): on for VO when the
    initial guess folder holds a previous result (``<trial>_states.sto``), as verification
    should reproduce that motion rather than drift inside the constraint bounds.
    ``evaluate_only``: build, evaluate the cost at the
    starting point, do not solve. ``accept_unconverged``: write the results of a solve that
    did not converge, stamped as unconverged (:mod:`nmsm.core.unconverged`), instead of only
    its last iterate. ``check_memory``: before building a problem to solve, stop
    with an :class:`InputError` naming the dominant dimension when its estimated memory
    (:mod:`nmsm.tools.treatment.memory`) exceeds what the machine has available.
    """

    results_directory: Path | None = None
    initial_guess_directory: Path | None = None
    tracked_quantities_directory: Path | None = None
    guess_directory: Path | None = None
    max_iterations: int | None = None
    tolerance: float | None = None
    hessian: str | None = None
    linear_solver: str | None = None
    print_level: int | None = None
    ipopt_options: dict[str, Any] = attrs.field(factory=dict)
    objective_scaling: str | float = "initial"
    rescale_prescribed_derivatives: bool = True
    warm_start: bool | None = None
    parallel: int = DEFAULT_PARALLEL
    evaluate_only: bool = False
    write_results: bool = True
    accept_unconverged: bool = False
    check_memory: bool = True


@attrs.define
class Prepared:
    """A built problem with what it was built from."""

    settings: Any
    tool: str
    plan: SolverPlan
    model: TreatmentModel
    files: TreatmentFiles
    data: TreatmentData
    built: TreatmentProblem
    terms: list[Term]
    warnings: list[str]


def _guess_splines(files: TreatmentFiles, kind: str, labels: Sequence[str]) -> ReferenceSplines | None:
    table = files.results.get(kind)
    if table is None or not all(table.has(label) for label in labels):
        return None
    return ReferenceSplines.from_table(table, labels)


def _check_states(settings: Any, model: TreatmentModel, files: TreatmentFiles) -> tuple[str, ...]:
    states = tuple(settings.states_coordinate_list)
    element = "<states_coordinate_list>"
    for c in states:
        if c not in model.coordinate_names:
            raise InputError(f"state coordinate '{c}' is not in the model", file=settings.settings_file,
                             element=element, expected="coordinates of " + str(settings.input_model_file))
        if c not in model.independent_coordinates:
            raise InputError(f"'{c}' is driven by a coordinate coupler constraint and cannot be a state",
                             file=settings.settings_file, element=element,
                             expected="independent coordinates (its independent coordinate instead)")
    if len(set(states)) != len(states):
        raise InputError("a coordinate is listed twice", file=settings.settings_file, element=element)
    missing = [c for c in model.independent_coordinates if not files.tracked_ik.has(c)]
    if missing:
        raise InputError(f"tracked kinematics lack model coordinate(s) {', '.join(missing)}",
                         file=files.tracked_ik.source, expected="a column for every independent model coordinate")
    return states


def _references(files: TreatmentFiles, model: TreatmentModel) -> dict[str, ReferenceSplines]:
    refs = {"coordinates": ReferenceSplines.from_table(files.tracked_ik, model.independent_coordinates)}
    if files.tracked_id is not None:
        refs["loads"] = ReferenceSplines.from_table(files.tracked_id)
    activations = files.results.get("combinedActivations")
    if activations is not None:
        refs["activations"] = ReferenceSplines.from_table(activations)
    if files.tracked_grf is not None:
        # centre-of-pressure columns are NaN in swing, where the force is 0: use 0 there
        table = files.tracked_grf
        data = np.where(np.isfinite(table.data), table.data, 0.0)
        time = table.time - table.time[0]
        refs["ground_reactions"] = ReferenceSplines(time, table.labels, data, str(table.source))
    return refs


def _initial_guess_splines(files: TreatmentFiles) -> dict[str, ReferenceSplines]:
    out = {}
    for kind in ("torqueControls", "synergyCommands", "combinedActivations", "muscleExcitations"):
        table = files.results.get(kind)
        if table is not None:
            out[kind] = ReferenceSplines.from_table(table)
    if files.initial_id is not None:
        out["loads"] = ReferenceSplines.from_table(files.initial_id)
    return out


def _controllers(settings: Any, tool: str, setup: ControllerSetup) -> list[Any]:
    registry = get_registry()
    by_element = {item.cls.settings_element: item.cls for item in registry.items("controller", tool)}
    out = []
    for element, attribute in CONTROLLER_ELEMENTS:
        element_settings = getattr(settings, attribute, None)
        if element_settings is None:
            continue
        cls = by_element.get(element)
        if cls is None:
            raise InputError(f"no controller plugin handles <{element}> in {tool}", file=settings.settings_file,
                             element=f"<{element}>", expected="an installed controller plugin for this element")
        out.append(cls.from_settings(element_settings, setup))
    return out


def _contact_models(tool: str, setup: ControllerSetup) -> list[Any]:
    """Every registered contact model's instances in this problem."""
    out = []
    for item in get_registry().items("contact", tool):
        out.extend(item.cls.discover(setup))
    return out


def _state_setup(settings: Any, files: TreatmentFiles, guess_files: TreatmentFiles, states: tuple[str, ...],
                 refs: dict[str, ReferenceSplines], plan: SolverPlan, guess_duration: float) -> StateSetup:
    tracked = refs["coordinates"]
    t_data = tracked.time
    q = tracked.values(t_data, 0, states)
    qd = tracked.values(t_data, 1, states)
    qdd = tracked.values(t_data, 2, states)
    lo_q, hi_q = range_bounds(q, RangeRule(settings.joint_position_range_scale_factor, settings.joint_position_minimum_range))
    lo_v, hi_v = range_bounds(qd, RangeRule(settings.joint_velocity_range_scale_factor, settings.joint_velocity_minimum_range))
    lo_a, hi_a = range_bounds(qdd, RangeRule(settings.joint_acceleration_range_scale_factor,
                                             settings.joint_acceleration_minimum_range))
    mesh = plan.mesh
    t_nodes = mesh.times("nodes") * guess_duration
    t_col = mesh.times("collocation") * guess_duration
    speed_labels = [speed_label(c) for c in states]
    state_splines = _guess_splines(guess_files, "states", list(states) + speed_labels)
    if state_splines is not None:
        guess = state_splines.values(t_nodes)
    else:
        ik = ReferenceSplines.from_table(guess_files.initial_ik, states)
        guess = np.hstack([ik.values(t_nodes, 0), ik.values(t_nodes, 1)])
    accel_splines = _guess_splines(guess_files, "accelerations", states)
    if accel_splines is not None:
        accel_guess = accel_splines.values(t_col)
        lo_a, hi_a = _covering(lo_a, hi_a, accel_guess)
    else:
        accel_guess = ReferenceSplines.from_table(guess_files.initial_ik, states).values(t_col, 2)
    if state_splines is not None:
        lo_v, hi_v = _covering(lo_v, hi_v, guess[:, len(states):])
    return StateSetup(np.r_[lo_q, lo_v], np.r_[hi_q, hi_v], lo_a, hi_a, guess, accel_guess)


#: where a previous result leaves the bounds, they are moved past it by this fraction of
#: the widened range, so that no variable starts on a bound
COVER_MARGIN = 0.1


def _covering(lower: np.ndarray, upper: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bounds (n,) widened to cover each column of ``values`` (m, n): a previous result's own
    speeds and accelerations, which the splined derivatives of its positions (the tracked
    data the bounds come from) do not always bound. Positions are not widened: a guess's
    positions outside their bounds are reported instead."""
    low, high = values.min(axis=0), values.max(axis=0)
    margin = COVER_MARGIN * (np.maximum(upper, high) - np.minimum(lower, low))
    return np.where(low < lower, low - margin, lower), np.where(high > upper, high + margin, upper)


def memory_estimate(data: TreatmentData, mesh: Any) -> MemoryEstimate:
    """The problem's memory estimate from its collocation points, state coordinates, muscles
    and contact springs (a contact model without springs counts as one)."""
    muscles = {m for c in data.controllers for m in c.muscle_names()}
    springs = sum(int(c.spring_count()) if hasattr(c, "spring_count") else 1 for c in data.contact_models)
    return MemoryEstimate(points=mesh.n_collocation, states=len(data.state_coordinates), muscles=len(muscles),
                          springs=springs)


def _formulation_warnings(tool: str, states: tuple[str, ...], terms: Sequence[Term],
                          controllers: Sequence[Any]) -> list[str]:
    """'neither controlled nor tracked' / VO 'both' diagnostics for state coordinates."""
    actuated = {c for ctrl in controllers for c in ctrl.controlled_coordinates()}
    tracked = {getattr(t, "coordinate", None) for t in terms
               if t.type in ("generalized_coordinate_tracking", "generalized_speed_tracking")}
    messages = []
    for c in states:
        if c not in actuated and c not in tracked:
            messages.append(f"state coordinate '{c}' is neither actuated by a controller nor tracked by a coordinate or "
                            "speed tracking term: only bounds and other terms determine its motion")
        elif tool == "VO" and c in actuated and c in tracked:
            messages.append(f"VO: state coordinate '{c}' is both controlled and tracked; Verification Optimization "
                            "should reproduce the motion from the controls alone (remove its tracking term)")
    return messages


def prepare(settings: Any, solver_settings: Any, options: TreatmentOptions | None = None,
            *, declare_extra: Any = None) -> Prepared:
    """Read the files named by ``settings`` and build the problem (no solve)."""
    from nmsm.tools.treatment.model_adapter import OsimTreatmentModel

    options = options or TreatmentOptions()
    tool = settings.tool_code
    plan = plan_from_settings(solver_settings.gpops, source=str(settings.optimal_control_solver_settings_file),
                              max_tolerance=DESIGN_MAX_TOLERANCE if tool == "DO" else MAX_TOLERANCE)
    model = OsimTreatmentModel(settings.input_model_file)
    tracked_dir = Path(options.tracked_quantities_directory or settings.tracked_quantities_directory)
    initial_dir = Path(options.initial_guess_directory or settings.initial_guess_directory)
    files = read_treatment_files(tracked_dir, initial_dir, settings.trial_name, model, settings_file=settings.settings_file)
    guess_files = files
    if options.guess_directory is not None:
        guess_files = read_treatment_files(tracked_dir, Path(options.guess_directory), settings.trial_name, model,
                                           settings_file=settings.settings_file)
    states = _check_states(settings, model, files)
    refs = _references(files, model)
    t_ref = duration(files.tracked_ik)
    guess_table = guess_files.results.get("states", guess_files.initial_ik)
    t_guess = duration(guess_table)
    final_range = getattr(settings, "final_time_range", None)
    problems: list[str] = []
    if final_range:
        lo_t, hi_t = float(final_range[0]), float(final_range[1])
        tf_guess = float(np.clip(t_guess, lo_t, hi_t))
        if tf_guess != t_guess:
            source = Path(getattr(guess_table, "source", None) or "the initial guess").name
            problems.append(f"final time <final_time_range>: initial guess {t_guess:.6g} s (duration of {source}) "
                            f"outside the bounds [{lo_t:.6g}, {hi_t:.6g}]")
    else:
        lo_t = hi_t = tf_guess = t_ref
        t_guess = t_ref if options.guess_directory is None else t_guess
    time_problems = guess_time_problems(guess_files, t_guess)
    if time_problems:
        warnings.warn(f"{settings.settings_file}: the initial guess does not cover the problem's time range (it is "
                      "read from its own start over the problem's duration, so IPOPT would start from another motion "
                      "than the tracked one; give a guess on the tracked data's times):\n  "
                      + "\n  ".join(time_problems), stacklevel=2)
    mesh = plan.mesh
    setup = ControllerSetup(
        tool=tool, model=model, collocation_times=mesh.times("collocation") * t_ref, reference_duration=t_ref,
        references=refs, initial_guess=_initial_guess_splines(files), settings_file=settings.settings_file,
        model_file=Path(settings.input_model_file), trial_name=settings.trial_name,
        osimx=getattr(settings, "input_osimx_file", None), synergy_weights=None, save_files=options.write_results,
    )
    setup.guess = _initial_guess_splines(guess_files)
    setup.guess_times = mesh.times("collocation") * t_guess
    setup.node_times = mesh.times("nodes") * t_ref
    setup.guess_node_times = mesh.times("nodes") * t_guess
    setup.extras["settings"] = settings
    setup.extras["files"] = files
    setup.extras["guess_files"] = guess_files
    controllers = _controllers(settings, tool, setup)
    data = TreatmentData(tool, model, states, refs, refs["coordinates"], t_ref, tf_guess, (lo_t, hi_t),
                         controllers=controllers, contact_models=_contact_models(tool, setup),
                         rescale_prescribed_derivatives=options.rescale_prescribed_derivatives)
    state_setup = _state_setup(settings, files, guess_files, states, refs, plan, t_guess)
    problems += check_guess_within("state", tuple(states) + tuple(speed_label(c) for c in states),
                                  state_setup.guess, state_setup.lower, state_setup.upper)
    problems += check_guess_within("acceleration", states, state_setup.accel_guess, state_setup.accel_lower,
                                   state_setup.accel_upper)
    for controller in controllers:
        for spec in controller.control_specs():
            problems += check_guess_within("control", (spec.name,), spec.guess, np.array([spec.lower]),
                                           np.array([spec.upper]))
        for state in controller.state_specs():
            problems += check_guess_within("state", (state.name,), state.guess, np.array([state.lower]),
                                           np.array([state.upper]))
    if problems:
        warnings.warn(f"{settings.settings_file}: the initial guess violates variable bounds (IPOPT starts from the "
                      "projection onto the bounds):\n  " + "\n  ".join(problems), stacklevel=2)
    for message in default_error_warnings(settings.cost_terms, tool):
        warnings.warn(message, stacklevel=2)
    terms = build_terms(list(settings.cost_terms), tool) + build_terms(list(settings.constraint_terms), tool)
    messages = _formulation_warnings(tool, states, terms, controllers)
    for message in messages:
        warnings.warn(f"{settings.settings_file}: {message}", stacklevel=2)
    if options.check_memory and not options.evaluate_only:  # the estimate is the solve's
        check_memory(memory_estimate(data, mesh), settings.settings_file)
    built = build_problem(data, mesh, state_setup, terms, name=f"{tool}_{settings.trial_name}",
                          normalize_cost_by_term_type=settings.normalize_cost_by_term_type,
                          parallel=options.parallel, declare_extra=declare_extra)
    return Prepared(settings, tool, plan, model, files, data, built, terms, time_problems + problems + messages)

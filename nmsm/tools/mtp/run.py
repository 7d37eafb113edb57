"""Muscle-Tendon Personalization from a settings file: ``run_settings(path, **options)``.

Steps (the original's ``MuscleTendonPersonalizationTool``):

1. read settings, model (+ input ``.osimx``), trials (ID, MA, EMG) of the muscles
   crossing ``coordinate_list``;
2. Muscle-Tendon Length Initialization when enabled (new l_o, l_ts, F0);
3. each enabled MTP task in index order (IPOPT, exact derivatives); after a task the
   length scale factors are absorbed into l_o, l_ts;
4. results written as the original writes them (:mod:`nmsm.tools.mtp.outputs`), staged, plus the settings file.

A stop (Ctrl-C) during task k+1 writes the results after task k, as step 4 would, into
``<results>/stopped_after_task_<k>/`` (``mtpSummary.txt`` says so) and nothing else: an
earlier complete run's files stay at the top; the next run retires the folder into
``superseded/`` with them.

``options``: ``results_directory`` (write elsewhere than the settings say),
``print_level`` (IPOPT, default 0), ``max_iterations`` (override), ``tolerance`` (IPOPT
``tol``, default 1e-6), ``emg_spline_stride`` (default 4), ``verbose`` (progress lines),
``keep_finished_on_stop`` (default true; the pipeline, which discards a stopped stage's
folder, passes false), ``accept_unconverged`` (default false).

A task (or MTLI) whose IPOPT solve did not converge stops the run: the results after that
task go into ``<results>/last_iterate/`` with ``diagnosis.txt``, the later tasks do not run,
and :class:`~nmsm.errors.SolverError` is raised (:mod:`nmsm.core.unconverged`); with
``accept_unconverged`` every task runs and the results are written, stamped as unconverged.
"""

from __future__ import annotations

import os
import sys
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.convergence import CONVERGENCE_TABLE, write_convergence_table
from nmsm.core.console import announce, summarize
from nmsm.core.results import STOPPED_FOLDER, ResultsDirectory
from nmsm.core.registry import build_terms
from nmsm.core.term import CostTerm
from nmsm.core.unconverged import diagnosis_text, settle, status_hints
from nmsm.errors import InputError, SolverError
from nmsm.io.layout import trial_table_folders
from nmsm.io.osimx import read_osimx
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.mtp import MuscleTendonPersonalizationSettings, MtpTask
from nmsm.tools.mtp import outputs
from nmsm.tools.mtp.data import check_same_frame_counts, find_prefixes, load_trial
from nmsm.tools.mtp.evaluation import check_fiber_lengths, evaluate, initial_fiber_lengths
from nmsm.tools.mtp.model_info import muscle_parameters, muscles_crossing
from nmsm.tools.mtp.mtli import MtliOptions, MtliResult, load_passive_trials, passive_moments_at, run_mtli
from nmsm.tools.mtp.mtli_model import PassiveTrial
from nmsm.tools.mtp.outcome import MtpOutcome, MtpSetup, TaskOutcome
from nmsm.tools.mtp.muscles import channel_map, resolve_groups
from nmsm.tools.mtp.problem import (
    MtpData,
    MtpState,
    TaskSettings,
    absorb_length_scales,
    build_task_problem,
    solve_task_problem,
    updated_state,
)
from nmsm.tools.mtp.summary import summary_lines
from nmsm.tools.mtp.synx import build_synergy_extrapolation

#: settings flag -> design block
TASK_FLAGS = {
    "optimize_electromechanical_delays": "electromechanical_delay",
    "optimize_activation_time_constants": "activation_time_constant",
    "optimize_activation_nonlinearity_constants": "activation_nonlinearity",
    "optimize_emg_scale_factors": "emg_scale",
    "optimize_optimal_fiber_lengths": "optimal_fiber_length_scale",
    "optimize_tendon_slack_lengths": "tendon_slack_length_scale",
}


def _log(verbose: bool, message: str) -> None:
    if verbose:
        print(f"[mtp] {message}", file=sys.stderr, flush=True)


def task_settings(task: MtpTask, synx_terms: Sequence[CostTerm]) -> TaskSettings:
    terms = tuple(t for t in build_terms(list(task.cost_terms), "MTP") if isinstance(t, CostTerm))
    return TaskSettings(
        optimize={block: bool(getattr(task, flag)) for flag, block in TASK_FLAGS.items()},
        cost_terms=terms,
        synx_terms=tuple(synx_terms),
        min_normalized_fiber_length=task.min_normalized_muscle_fiber_length,
        max_normalized_fiber_length=task.max_normalized_muscle_fiber_length,
    )


def prepare(settings_file: str | os.PathLike[str], *, emg_spline_stride: int = 4) -> MtpSetup:
    """Read settings, model, osimx and data; validate names and shapes."""
    from nmsm.model import load_model

    doc = read_settings_document(settings_file)
    settings = MuscleTendonPersonalizationSettings.from_document(doc)
    if not settings.tasks:
        raise InputError("no enabled <MTPTask>", file=settings_file, element="<MTPTaskList>",
                         expected="at least one task with <is_enabled>true</is_enabled>")
    model = load_model(settings.input_model_file)
    osimx = read_osimx(settings.input_osimx_file) if settings.input_osimx_file else None
    coordinates = tuple(settings.coordinate_list)
    names = muscles_crossing(model, coordinates)
    muscles = muscle_parameters(model, names, osimx)
    where = {"model_file": str(settings.input_model_file), "settings_file": str(settings.settings_file)}
    groups = model.groups
    collected = resolve_groups(settings.collected_emg_channel_muscle_groups, groups, names,
                               setting="collected_emg_channel_muscle_groups", **where, drop_empty=False)
    synx_settings = settings.synergy_extrapolation
    missing = resolve_groups(settings.missing_emg_channel_muscle_groups, groups, names,
                             setting="missing_emg_channel_muscle_groups", **where)
    channels = channel_map(names, collected, missing)
    if missing and not synx_settings.is_enabled:
        warnings.warn(
            "synergy extrapolation is off: muscles of <missing_emg_channel_muscle_groups> ("
            + ", ".join(names[i] for g in missing for i in g.indices) + ") get zero excitation",
            stacklevel=2,
        )
    activation_groups = resolve_groups(settings.activation_muscle_groups, groups, names,
                                       setting="activation_muscle_groups", **where)
    fiber_groups = resolve_groups(settings.normalized_fiber_length_muscle_groups, groups, names,
                                  setting="normalized_fiber_length_muscle_groups", **where)
    prefixes = find_prefixes(settings.data_directory, settings.trial_prefixes)
    channel_names = [g.name for g in collected]
    trials = tuple(load_trial(settings.data_directory, p, coordinates, names, channel_names) for p in prefixes)
    check_same_frame_counts(trials)
    synx = None
    if synx_settings.is_enabled:
        synx = build_synergy_extrapolation(
            [t.emg for t in trials],
            [t.name for t in trials],
            method=synx_settings.matrix_factorization_method,
            n_synergies=int(synx_settings.number_of_synergies),
            extrapolation_categorization=str(synx_settings.synergy_extrapolation_categorization),
            residual_categorization=str(synx_settings.residual_categorization),
            missing_muscles=[g.indices for g in missing],
            channel_muscles=[g.indices for g in collected],
        )
    data = MtpData(muscles, coordinates, trials, channels, activation_groups, fiber_groups, synx,
                   float(settings.v_max_factor), int(emg_spline_stride))
    check_fiber_lengths(data, stage="MTP input",
                        source=str(settings.input_osimx_file or settings.input_model_file))
    synx_terms = tuple(t for t in build_terms(list(synx_settings.cost_terms), "SynX") if isinstance(t, CostTerm)) \
        if synx_settings.is_enabled else ()
    tasks = tuple(task_settings(t, synx_terms) for t in settings.tasks)
    mtli = settings.muscle_tendon_length_initialization
    passive: tuple[PassiveTrial, ...] = ()
    mtli_terms: tuple[CostTerm, ...] = ()
    if mtli.is_enabled:
        mtli_terms = tuple(t for t in build_terms(list(mtli.cost_terms), "MTLI") if isinstance(t, CostTerm))
        if mtli.passive_data_input_directory is not None:
            passive = load_passive_trials(mtli.passive_data_input_directory, coordinates, names)
    return MtpSetup(settings, model.name, osimx, muscles, data, passive, tasks, mtli_terms)


def mtli_options(setup: MtpSetup) -> MtliOptions:
    m = setup.settings.muscle_tendon_length_initialization
    return MtliOptions(
        max_normalized_fiber_length=m.max_normalized_muscle_fiber_length if m.max_normalized_muscle_fiber_length is not None else 1.0,
        min_normalized_fiber_length=m.min_normalized_muscle_fiber_length if m.min_normalized_muscle_fiber_length is not None else 0.6,
        optimize_maximum_muscle_stress=bool(m.optimize_maximum_muscle_stress),
        update_max_isometric_force=bool(m.optimize_isometric_max_force),
        absolute_lengths=bool(m.optimize_absolute_length_changes),
        maximum_muscle_stress=float(m.maximum_muscle_stress),
    )


def initialize_lengths(setup: MtpSetup) -> tuple[MtpData, MtliResult | None]:
    """Run MTLI if enabled; the data's muscles then carry the new l_o, l_ts, F0."""
    if not setup.settings.muscle_tendon_length_initialization.is_enabled:
        return setup.data, None
    gait = [t.muscle_tendon_length for t in setup.data.trials]
    result = run_mtli(setup.data.muscles, gait, setup.passive_trials, setup.data.fiber_length_groups,
                      setup.mtli_terms, mtli_options(setup))
    data = attrs.evolve(setup.data, muscles=result.muscles)
    check_fiber_lengths(data, stage="after MTLI")
    return data, result


def solve_tasks(
    setup: MtpSetup,
    data: MtpData,
    *,
    state: MtpState | None = None,
    print_level: int = 0,
    max_iterations: int | None = None,
    tolerance: float = 1e-6,
    verbose: bool = False,
    on_task: Any = None,
    stop_unconverged: bool = False,
) -> tuple[MtpData, MtpState, list[TaskOutcome]]:
    """Run every task in order from ``state`` (default: the original's initial values);
    ``stop_unconverged``: stop after the first task whose solve did not converge."""
    state = state or MtpState.initial(data)
    initial_lengths = initial_fiber_lengths(data)
    outcomes = []
    for k, task in enumerate(setup.tasks, start=1):
        _log(verbose, f"task {k}: building the problem")
        problem, _ = build_task_problem(data, state, task, initial_lengths, name=f"MTP_task_{k}")
        _log(verbose, f"task {k}: {problem.n_variables} variables; solving with IPOPT")
        solution = solve_task_problem(
            problem,
            max_iterations=max_iterations if max_iterations is not None else setup.settings.max_iterations,
            tolerance=tolerance,
            print_level=print_level,
        )
        if not all(np.all(np.isfinite(v)) for v in solution.values.values()):
            raise SolverError(f"MTP task {k} returned non-finite values ({solution.status})")
        state = updated_state(state, solution.values)
        outcome = TaskOutcome(k, solution.cost, dict(solution.term_costs), solution.status, solution.iterations,
                              solution.wall_time, solution.history, bool(solution.success))
        outcomes.append(outcome)
        _log(verbose, f"task {k}: {solution.status}, cost {solution.cost:.6g}, {solution.iterations} iterations, "
                      f"{solution.wall_time:.1f} s")
        if on_task is not None:
            on_task(k, data, state, outcome)
        data, state = absorb_length_scales(data, state)
        if stop_unconverged and not outcome.converged:
            break
    return data, state, outcomes


def output_osimx_name(setup: MtpSetup) -> str:
    base = Path(setup.settings.input_osimx_file).stem if setup.settings.input_osimx_file else \
        Path(setup.settings.input_model_file).stem
    return f"{base}_mtp.osimx"


def write_results(outcome: MtpOutcome, results: ResultsDirectory, *, stopped_after: int | None = None,
                  note: str | None = None, unconverged: str | None = None) -> None:
    """Write ``outcome`` into ``results`` as one task (``stopped_after``: a stopped run's
    results after that task, :meth:`ResultsDirectory.stopped_task`); ``note``: a first line
    of ``mtpSummary.txt``; ``unconverged``: the stamp of accepted unconverged results."""
    task = (results.task("mtp_results", unconverged=unconverged) if stopped_after is None
            else results.stopped_task(stopped_after))
    with task as stage:
        write_result_files(stage, outcome, note)


def write_result_files(stage: Path, outcome: MtpOutcome, note: str | None = None) -> None:
    """The result files of ``outcome`` in the folder ``stage`` (the original's and ``mtpSummary.txt``)."""
    setup = outcome.setup
    trial_times = [t.time for t in outcome.data.trials]
    outputs.analysis_files(stage, outcome.data, outcome.plain, outcome.synx, trial_times)
    outputs.parameter_file(stage, outcome.state, outcome.final_muscles, setup.model_muscles)
    if setup.passive_trials:
        modeled = passive_moments_at(outcome.final_muscles, setup.passive_trials)
        outputs.passive_moment_files(stage, outcome.data.coordinates, setup.passive_trials, modeled)
    outputs.osimx_file(
        stage,
        output_osimx_name(setup),
        setup.model_name,
        str(setup.settings.input_model_file),
        outcome.state,
        outcome.final_muscles,
        write_max_isometric_force=outcome.mtli is not None and mtli_options(setup).update_max_isometric_force,
        base=setup.input_osimx,
    )
    lines = [note] if note else []
    lines += [f"task {t.index}: {t.status}; cost {t.cost:.10g}; {t.iterations} iterations; {t.wall_time:.2f} s"
              for t in outcome.tasks]
    for t in outcome.tasks:
        lines += [f"  task {t.index} {name}: {value:.10g}" for name, value in t.term_costs.items()]
    lines.append(f"total wall time: {outcome.wall_time:.2f} s")
    (stage / "mtpSummary.txt").write_text("\n".join(lines) + "\n", encoding="utf-8")
    histories = {"mtli": outcome.mtli.solution.history} if outcome.mtli is not None else {}
    histories.update({f"task_{t.index}": t.history for t in outcome.tasks})
    write_convergence_table(stage / CONVERGENCE_TABLE, histories)


def run_settings(settings_file: str | os.PathLike[str], **options: Any) -> MtpOutcome:
    """Run MTP (and MTLI) from ``settings_file``; see the module docstring for ``options``."""
    start = time.perf_counter()
    verbose = bool(options.pop("verbose", False))
    results_dir = options.pop("results_directory", None)
    stride = int(options.pop("emg_spline_stride", 4))
    print_level = int(options.pop("print_level", 0))
    max_iterations = options.pop("max_iterations", None)
    tolerance = float(options.pop("tolerance", 1e-6))
    keep_stopped = bool(options.pop("keep_finished_on_stop", True))
    accept = bool(options.pop("accept_unconverged", False))
    if options:
        raise TypeError(f"unknown MTP options: {', '.join(options)}")
    setup = prepare(settings_file, emg_spline_stride=stride)
    target = Path(results_dir) if results_dir is not None else Path(setup.settings.results_directory)
    inputs = [setup.settings.input_model_file, settings_file]
    if setup.settings.input_osimx_file:
        inputs.append(setup.settings.input_osimx_file)
    settings = setup.settings
    folders = trial_table_folders(settings.data_directory, "<data_directory>")
    passive = settings.muscle_tendon_length_initialization.passive_data_input_directory
    if settings.muscle_tendon_length_initialization.is_enabled and passive is not None:
        folders.update(trial_table_folders(passive, "<passive_data_input_directory>"))
    results = ResultsDirectory(target, inputs=inputs, input_folders=folders,
                               input_roots={"<data_directory>": settings.data_directory}, record="mtp",
                               settings_file=settings_file)
    _log(verbose, f"{len(setup.data.trials)} trials, {setup.data.muscles.n_muscles} muscles, "
                  f"{len(setup.data.coordinates)} coordinates, SynX {'on' if setup.data.synx else 'off'}")
    announce("MTP", settings=settings_file, model=settings.input_model_file,
             trials=[t.name for t in setup.data.trials],
             problem=f"{setup.data.muscles.n_muscles} muscles, {len(setup.data.coordinates)} coordinates, "
                     f"{sum(t.time.size for t in setup.data.trials)} frames, {len(setup.tasks)} task(s), "
                     f"SynX {'on' if setup.data.synx else 'off'}")
    start_data, mtli = initialize_lengths(setup)
    failures = []
    if mtli is not None:
        _log(verbose, f"MTLI: {mtli.solution.status}, cost {mtli.solution.cost:.6g}")
        if not mtli.solution.success:
            failures.append(f"MTLI: IPOPT {mtli.solution.status} after {mtli.solution.iterations} iterations")
    finished: list[tuple[MtpData, MtpState, TaskOutcome]] = []
    try:
        if failures and not accept:  # the tasks would start from an unconverged MTLI
            data, state, tasks = start_data, MtpState.initial(start_data), []
        else:
            data, state, tasks = solve_tasks(setup, start_data, print_level=print_level,
                                             max_iterations=max_iterations, tolerance=tolerance, verbose=verbose,
                                             on_task=lambda k, d, s, o: finished.append((d, s, o)),
                                             stop_unconverged=not accept)
    except KeyboardInterrupt:
        if keep_stopped:
            _keep_finished_tasks(setup, start_data, mtli, finished, results, start)
        raise
    failures += [f"MTP task {t.index}: IPOPT {t.status} after {t.iterations} iterations"
                 for t in tasks if not t.converged]
    plain, synx = evaluate(data, state)
    outcome = MtpOutcome(setup, start_data, data, state, mtli, tuple(tasks), plain, synx, results.path,
                         time.perf_counter() - start)
    stamp = settle(results, settings_file, failures, accept=accept,
                   write=lambda folder: write_result_files(folder, outcome),
                   diagnosis=lambda note: _diagnosis(outcome, note))
    write_results(outcome, results, unconverged=stamp)
    results.copy_in(settings_file, Path(settings_file).name)
    summarize("MTP", summary_lines(outcome))
    return outcome


def _diagnosis(outcome: MtpOutcome, note: str) -> str:
    """``diagnosis.txt`` of an unconverged run: hints, then each solve's status and costs."""
    lines = []
    hints: list[str] = []
    if outcome.mtli is not None:
        m = outcome.mtli.solution
        lines.append(f"MTLI: {m.status}; cost {m.cost:.10g}; {m.iterations} iterations")
        if not m.success:
            hints += status_hints(m.status, "the MTLI iteration limit")
    for t in outcome.tasks:
        lines.append(f"task {t.index}: {t.status}; cost {t.cost:.10g}; {t.iterations} iterations; "
                     f"{t.wall_time:.2f} s")
        lines += [f"  task {t.index} {name}: {value:.10g}" for name, value in t.term_costs.items()]
        if not t.converged:
            hints += status_hints(t.status, "<max_iterations>")
    remaining = len(outcome.setup.tasks) - len(outcome.tasks)
    if remaining:
        lines.append(f"{remaining} later task(s) not run: they would start from this unconverged result")
    return diagnosis_text(note, list(dict.fromkeys(hints)), "\n".join(lines))



def _keep_finished_tasks(setup: MtpSetup, start_data: MtpData, mtli: MtliResult | None,
                         finished: Sequence[tuple[MtpData, MtpState, TaskOutcome]], results: ResultsDirectory,
                         start: float) -> None:
    """A stop (Ctrl-C) during task k+1: write the results after task k (as the tool would
    after its last task) into ``<results>/stopped_after_task_<k>/``, so finished tasks are
    not lost; nothing when no task finished. An earlier complete run's files stay in place;
    the next run retires the folder (:meth:`ResultsDirectory.stopped_task`)."""
    if not finished:
        return
    data, state, _ = finished[-1]
    data, state = absorb_length_scales(data, state)
    plain, synx = evaluate(data, state)
    tasks = tuple(outcome for _, _, outcome in finished)
    outcome = MtpOutcome(setup, start_data, data, state, mtli, tasks, plain, synx, results.path,
                         time.perf_counter() - start)
    k = len(finished)
    write_results(outcome, results, stopped_after=k,
                  note=f"stopped during task {k + 1} of {len(setup.tasks)}: results after task {k}")
    print(f"nmsm: MTP stopped during task {k + 1}; the results after task {k} are in "
          f"{results.path / STOPPED_FOLDER.format(k=k)}", file=sys.stderr)

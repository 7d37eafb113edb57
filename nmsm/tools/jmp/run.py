"""Joint Model Personalization from a settings file: ``nmsm run JMPSettings.xml``.

    from nmsm.tools.jmp.run import run_settings
    run = run_settings("JMPSettingsSimultaneous.xml", results_directory="out/jmp")
    run.output_model                      # the personalized .osim
    print(run.report)

Tasks run in ``<index>`` order, each on the model the previous one wrote. Results (written
through :class:`~nmsm.core.results.ResultsDirectory`, task by task, never over an input)::

    <results_directory>/
        <output_model_file>                 the personalized model (last task's)
        <settings file>                     a copy of the settings
        jmp_report.txt                      errors before/after per task and joint, parameters
        jmp_results.json                    the same numbers, machine-readable (plots read it)
        commandWindowOutput.txt             the run's log
        task<i>_<name>/                     per task: ik_before.mot, ik_after.mot,
                                            marker_errors_before.sto, marker_errors_after.sto (m),
                                            and the task's model when it is not the last task

Figures are drawn from these files afterwards (``nmsm plot RESULTS``, ``nmsm.run(...,
plots=True)``: :func:`nmsm.plots.jmp.plot_jmp_results`).

Optimizer options of the settings are honoured: ``function_tolerance`` (relative cost
change), ``step_tolerance`` (step relative to the variables), ``optimality_tolerance``
(infinity norm of the projected ``J^T r``, half the gradient of the normalized cost),
``max_function_evaluations`` (residual and exact-Jacobian evaluations) and ``accuracy``
(the IK before/after, see :func:`~nmsm.tools.jmp.ik.tolerances_for_accuracy`).
``diff_min_change`` is the minimum finite-difference step of the original's solver; nmsm
differentiates exactly, so it has no counterpart (the log says so).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import attrs

from nmsm.core.convergence import CONVERGENCE_TABLE, format_convergence_table
from nmsm.core.console import announce, console_enabled, summarize
from nmsm.core.results import ResultsDirectory
from nmsm.core.unconverged import diagnosis_text, settle, status_hints
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.jmp import JointModelPersonalizationSettings
from nmsm.io.storage import write_storage
from nmsm.tools.jmp.ik import marker_error_table, write_motion
from nmsm.core.backends.levenberg_marquardt import Tolerances
from nmsm.tools.jmp.report import error_rows, format_task, rows_to_json, write_json
from nmsm.tools.jmp.task import TaskResult, run_task

REPORT_FILE = "jmp_report.txt"
RESULTS_FILE = "jmp_results.json"
LOG_FILE = "commandWindowOutput.txt"
#: iteration limit (the original's MaxIterations is 4e6, i.e. effectively the evaluation limit)
DEFAULT_MAX_ITERATIONS = 1000


@attrs.frozen(eq=False)
class JmpRun:
    """A finished run: settings, task results, the output model, the report text."""

    settings: JointModelPersonalizationSettings
    tasks: tuple[TaskResult, ...]
    output_model: Path
    results_directory: Path
    report: str
    wall_time: float


def read_settings(path: str | os.PathLike[str]) -> JointModelPersonalizationSettings:
    """Validated JMP settings (old schemas upgraded, paths resolved)."""
    return JointModelPersonalizationSettings.from_document(read_settings_document(path))


def tolerances_from_settings(settings: JointModelPersonalizationSettings, *,
                             max_iterations: int = DEFAULT_MAX_ITERATIONS) -> Tolerances:
    return Tolerances(xtol=settings.step_tolerance, ftol=settings.function_tolerance,
                      gtol=settings.optimality_tolerance, max_evaluations=settings.max_function_evaluations,
                      max_iterations=max_iterations)


def _folder_name(task: Any, position: int) -> str:
    safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in (task.name or "task"))
    return f"task{task.index if task.index is not None else position}_{safe}"


def _task_files(stage: Path, folder: str, result: TaskResult) -> None:
    target = stage / folder
    target.mkdir(parents=True, exist_ok=True)
    write_motion(target / "ik_before.mot", result.before)
    write_motion(target / "ik_after.mot", result.after)
    write_storage(target / "marker_errors_before.sto", marker_error_table(result.before), name="MarkerErrors")
    write_storage(target / "marker_errors_after.sto", marker_error_table(result.after), name="MarkerErrors")


def _task_summary(result: TaskResult, folder: str) -> tuple[str, dict[str, Any]]:
    model = result.design.parameters.model
    joints = [j.name for j in result.task.joints]
    rows = error_rows(model, joints, result.trial.names, result.before.marker_errors, result.after.marker_errors)
    sol = result.solution
    solver = {"status": sol.status, "converged": sol.converged, "iterations": sol.iterations,
              "evaluations": sol.evaluations, "wall_time": sol.wall_time, "initial_cost": sol.initial_cost,
              "cost": sol.cost, "reseated_frames": sol.reseated_frames}
    trial = result.trial
    title = (f"{result.label}: {result.task.marker_file_name.name}, {trial.time[0]:g}-{trial.time[-1]:g} s, "
             f"{trial.n_frames} frames, {trial.n_markers} markers")
    text = format_task(title, rows, result.design.variables, result.design.initial, result.values, solver,
                       result.notes)
    data = {"label": result.label, "folder": folder, "marker_file": str(result.task.marker_file_name),
            "time": [float(trial.time[0]), float(trial.time[-1])], "frames": trial.n_frames,
            "markers": list(trial.names), "joints": joints, "errors": rows_to_json(rows), "solver": solver,
            "parameters": [{"label": v.label, "kind": v.kind, "target": v.target, "component": v.component,
                            "initial": v.initial, "final": float(x), "lower": v.lower, "upper": v.upper}
                           for v, x in zip(result.design.variables, result.values)],
            "coordinates": {"free": list(result.before.free_names), "locked": list(result.before.locked_names),
                            "no_marker_sensitivity": list(result.before.insensitive_names)},
            "notes": list(result.notes), "model": result.output.name}
    return text, data


def run_settings(path: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
                 function_tolerance: float | None = None, step_tolerance: float | None = None,
                 optimality_tolerance: float | None = None, max_function_evaluations: int | None = None,
                 max_iterations: int = DEFAULT_MAX_ITERATIONS, accuracy: float | None = None,
                 quiet: bool = False, accept_unconverged: bool = False) -> JmpRun:
    """Run JMP as the settings file ``path`` says (see module docstring).

    Keyword options override the settings (``results_directory``, the optimizer tolerances,
    ``accuracy``); ``quiet`` silences the log on stdout.
    A task whose optimization stopped before its tolerances (at ``max_function_evaluations``
    or ``max_iterations``) ends the run: its files and model go into
    ``<results>/last_iterate/`` with ``diagnosis.txt`` and :class:`~nmsm.errors.SolverError`
    is raised, unless ``accept_unconverged`` (then the results of that task and every later
    file are stamped as unconverged; :mod:`nmsm.core.unconverged`).
    """
    start = time.perf_counter()
    settings = read_settings(path)
    overrides = {"function_tolerance": function_tolerance, "step_tolerance": step_tolerance,
                 "optimality_tolerance": optimality_tolerance, "max_function_evaluations": max_function_evaluations,
                 "accuracy": accuracy}
    settings = attrs.evolve(settings, **{k: v for k, v in overrides.items() if v is not None})
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    out_dir = Path(settings.results_directory)
    inputs = [settings.input_model_file, settings.settings_file, *[t.marker_file_name for t in settings.tasks]]
    results = ResultsDirectory(out_dir, inputs=inputs, record="jmp", settings_file=settings.settings_file)
    results.reserve(settings.output_model_path.name, element="<output_model_file>")  # before solving
    log_lines: list[str] = []

    def log(text: str) -> None:
        log_lines.append(text)
        if not quiet and console_enabled():
            print(f"  {text}", flush=True)

    tolerances = tolerances_from_settings(settings, max_iterations=max_iterations)
    if not quiet:
        announce("JMP", settings=settings.settings_file, model=settings.input_model_file,
                 trials=[Path(t.marker_file_name).name for t in settings.tasks],
                 problem=f"{len(settings.tasks)} task(s), allowable marker error {settings.allowable_error:g} m")
    log_lines.append(f"Joint Model Personalization: {settings.settings_file}")
    log_lines.append(f"model {settings.input_model_file}; {len(settings.tasks)} task(s); allowable error "
                     f"{settings.allowable_error:g} m")
    log(f"solver: exact-Jacobian Levenberg-Marquardt, function tolerance {tolerances.ftol:g}, step tolerance "
        f"{tolerances.xtol:g}, optimality tolerance {tolerances.gtol:g}, max evaluations {tolerances.max_evaluations}"
        f"; IK accuracy {settings.accuracy if settings.accuracy is not None else 'default (1e-5)'}"
        f"; diff_min_change {settings.diff_min_change:g} not used (no finite differences)")
    model_file = Path(settings.input_model_file)
    task_results: list[TaskResult] = []
    blocks: list[str] = []
    summaries: list[dict[str, Any]] = []
    final_name = settings.output_model_path.name
    failures: list[str] = []
    stamp: str | None = None
    for position, task in enumerate(settings.tasks, start=1):
        last = position == len(settings.tasks)
        folder = _folder_name(task, position)
        relative = Path(final_name) if last else Path(folder) / f"{Path(final_name).stem}_after_{folder}.osim"
        with _work_folder(results) as work:
            result = run_task(model_file, task, position, allowable_error=settings.allowable_error,
                              tolerances=tolerances, ik_accuracy=settings.accuracy, output=work / relative,
                              settings_file=str(settings.settings_file), log=log)
            _task_files(work, folder, result)
            if not result.solution.converged:
                failures.append(f"{result.label}: {result.solution.status} after {result.solution.iterations} "
                                f"iterations, {result.solution.evaluations} evaluations")
                stamp = settle(results, settings.settings_file, failures, accept=accept_unconverged,
                               write=lambda target: shutil.copytree(work, target, dirs_exist_ok=True),
                               diagnosis=lambda note: _diagnosis(note, result, folder, len(settings.tasks) - position))
            with results.task(folder, unconverged=stamp) as stage:
                shutil.copytree(work, stage, dirs_exist_ok=True)
        result = attrs.evolve(result, output=results.path / relative)
        model_file = result.output
        text, data = _task_summary(result, folder)
        blocks.append(text)
        summaries.append(data)
        task_results.append(result)
    wall = time.perf_counter() - start
    header = (f"Joint Model Personalization report\nsettings: {settings.settings_file}\n"
              f"input model: {settings.input_model_file}\noutput model: {results.path / final_name}\n"
              f"allowable error: {settings.allowable_error:g} m; total time {wall:.1f} s\n")
    report = header + "\n" + "\n".join(blocks)
    log_lines.append(report)
    if not quiet:
        summarize("JMP", summary_lines(task_results, wall))
    results.write_text(REPORT_FILE, report, unconverged=stamp)
    results.write_text(CONVERGENCE_TABLE, format_convergence_table(
        {_folder_name(r.task, k): r.solution.history for k, r in enumerate(task_results, start=1)}),
        unconverged=stamp)
    write_summary(results, settings, summaries, wall, unconverged=stamp)
    settings_copy = results.path / Path(settings.settings_file).name
    if settings_copy.resolve() != Path(settings.settings_file).resolve():
        results.copy_in(settings.settings_file)
    results.write_text(LOG_FILE, "\n".join(log_lines) + "\n", unconverged=stamp)
    return JmpRun(settings=settings, tasks=tuple(task_results), output_model=results.path / final_name,
                  results_directory=results.path, report=report, wall_time=wall)


def summary_lines(tasks: Sequence[TaskResult], wall_time: float) -> list[str]:
    """The console summary: per task the solver's outcome, the marker RMS before and after
    (mm) and the parameters that ended at a bound; the total time."""
    lines = []
    for result in tasks:
        solution = result.solution
        lines.append(f"{result.label}: {solution.status} after {solution.iterations} iterations; marker RMS "
                     f"{1000 * result.before.marker_rms():.2f} -> {1000 * result.after.marker_rms():.2f} mm")
        at_bound = [v.label for v, value in zip(result.design.variables, solution.p)
                    if min(abs(value - v.lower), abs(value - v.upper)) <= 1e-9]
        lines.append(f"  parameters at a bound: {', '.join(at_bound) if at_bound else 'none'} "
                     f"(of {len(result.design.variables)})")
    lines.append(f"total time {wall_time:.1f} s; report: {REPORT_FILE}")
    return lines


@contextlib.contextmanager
def _work_folder(results: ResultsDirectory) -> Iterator[Path]:
    """A hidden folder inside the results folder where a task writes before its files are
    committed (or kept as the last iterate); removed however the block ends."""
    work = Path(tempfile.mkdtemp(prefix=".jmp-task-", dir=results.ensure()))
    try:
        yield work
    except BaseException as exc:
        shutil.rmtree(work, ignore_errors=True)
        results.remove_if_unused()
        if isinstance(exc, OSError) and exc.filename is None:  # e.g. a full disk while writing: name the folder
            exc.filename = str(results.path)
        raise
    shutil.rmtree(work, ignore_errors=True)


def _diagnosis(note: str, result: TaskResult, folder: str, not_run: int) -> str:
    """``diagnosis.txt`` of an unconverged task: hints, then the task's report."""
    hints = status_hints(result.solution.status, "<max_function_evaluations>")
    text, _ = _task_summary(result, folder)
    if not_run:
        text += f"\n{not_run} later task(s) not run: they would start from this unconverged model"
    return diagnosis_text(note, hints, text)


def write_summary(results: ResultsDirectory, settings: JointModelPersonalizationSettings,
                  tasks: Sequence[dict[str, Any]], wall_time: float, *, unconverged: str | None = None) -> None:
    with results.task("summary", unconverged=unconverged) as stage:
        write_json(stage / RESULTS_FILE, {
            "tool": "JointModelPersonalization", "settings": str(settings.settings_file),
            "input_model": str(settings.input_model_file), "output_model": settings.output_model_path.name,
            "allowable_error": settings.allowable_error, "wall_time": wall_time, "tasks": list(tasks)})


"""Ground Contact Personalization from a settings file: ``run_settings(path, **options)``
(``nmsm run`` dispatches ``<GroundContactPersonalizationTool>`` here).

Steps: read the settings (old schemas upgraded), the model, motion and ground reactions;
build each enabled foot (two-segment foot model, springs, experimental kinematics and
reactions on its window); optionally initialize the resting spring length; run the enabled
tasks in index order, each starting from the previous solution; write the results
(:mod:`nmsm.tools.gcp.outputs`) through a staged results folder and copy the settings file
there. A stop (Ctrl-C) during task k+1 writes the results after task k, as the run would,
into ``<results>/stopped_after_task_<k>/`` (with two feet solved separately: only when every
foot has a finished task; the earlier feet's results are after all their tasks) and
nothing else: an earlier complete run's files stay at the top; the next run retires the
folder into ``superseded/`` with them.

Options:

``results_directory``  override the settings' results folder (e.g. when it is read-only);
``feet``               ``"separately"`` (default: one problem per foot, each with its own
                       spring constants, damping, friction and resting length; a foot's
                       result is the one a settings file with that foot alone gives) or
                       ``"together"`` (as the original: one problem in which the feet share
                       those properties; docs/gcp.md "Both feet" compares the two);
``spring_locations``   an ``.osimx`` whose contact surfaces give the spring bodies and
                       locations (default: the settings' ``input_osimx_file`` when it has a
                       surface on the foot's hindfoot, else the marker-based grid of
                       :mod:`nmsm.tools.gcp.spring_grid`);
``max_iterations``     override the settings' iteration limit of every task;
``update_motion``      re-run IK with the modeled foot markers (default True);
``verbose``            print each solver iteration;
``keep_finished_on_stop`` default True (the pipeline, which discards a stopped stage's
                       folder, passes False);
``accept_unconverged`` write the results although a task's solve stopped before its
                       tolerances (at ``max_iterations`` residual evaluations), stamped as
                       unconverged; by default such a run stops after that task and writes
                       its results into ``<results>/last_iterate/`` with ``diagnosis.txt``
                       and raises :class:`~nmsm.errors.SolverError` (:mod:`nmsm.core.unconverged`).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import attrs

from nmsm.core.convergence import CONVERGENCE_TABLE, ConvergenceHistory, write_convergence_table
from nmsm.core.console import announce, summarize
from nmsm.core.problem import Solution
from nmsm.core.results import STOPPED_FOLDER, ResultsDirectory
from nmsm.core.registry import build_terms
from nmsm.core.unconverged import diagnosis_text, settle, status_hints
from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel, read_osimx
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.osim import load_model
from nmsm.tools.gcp import report
from nmsm.tools.gcp.data import read_ground_reactions, read_motion
from nmsm.tools.gcp.inputs import FootInputs, build_foot_inputs, check_equal_spring_counts
from nmsm.tools.gcp.problem import build_task_problem, solve_task, solver_options, updated_state
from nmsm.tools.gcp.rest_length import initialize_resting_length
from nmsm.tools.gcp.state import GcpState
from nmsm.tools.gcp.values import FootValues, foot_values
from nmsm.tools.gcp.write import write_results

FEET_MODES = ("together", "separately")


@attrs.frozen(eq=False)
class GroupResult:
    """One optimized group of feet: inputs, final state, each task's solution, final values."""

    feet: list[FootInputs]
    state: GcpState
    solutions: list[Solution]
    values: list[FootValues]
    task_seconds: list[float]


@attrs.frozen(eq=False)
class GcpRunResult:
    """What :func:`run_settings` returns: the settings, the groups, the results folder and
    the error table (:mod:`nmsm.tools.gcp.report`)."""

    settings: GroundContactPersonalizationSettings
    groups: list[GroupResult]
    results_directory: Path
    errors: dict[int, dict[str, float]]
    wall_time: float

    @property
    def final_cost(self) -> float:
        """Sum over the groups of the last task's cost."""
        return float(sum(g.solutions[-1].cost for g in self.groups if g.solutions))


def task_terms(settings: GroundContactPersonalizationSettings) -> list[list[Any]]:
    """Each task's registered cost terms, checked before anything is optimized."""
    out = []
    for k, task in enumerate(settings.tasks, start=1):
        terms = build_terms(list(task.cost_terms), "GCP")
        if not terms:
            raise InputError(f"GCP task {task.index or k} has no enabled cost term", file=settings.settings_file,
                             line=task.source.line, element="<RCNLCostTermSet>", expected="at least one enabled term")
        if not any(task.design_flags.values()):
            raise InputError(f"GCP task {task.index or k} optimizes nothing", file=settings.settings_file,
                             line=task.source.line, element="<GCPTask>", expected="at least one design flag true")
        out.append(terms)
    return out


def optimize_group(settings: GroundContactPersonalizationSettings, feet: list[FootInputs], *,
                   max_iterations: int | None = None, verbose: bool = False,
                   on_task: Callable[[GroupResult], None] | None = None,
                   stop_unconverged: bool = False) -> GroupResult:
    """Initialize and run every task for ``feet`` optimized together; ``on_task`` gets the
    group as it stands after each finished task; ``stop_unconverged``: stop after the first
    task whose solve did not converge."""
    check_equal_spring_counts(feet, settings.settings_file)
    terms_per_task = task_terms(settings)
    state = GcpState.initial(settings, feet)
    if settings.initialize_resting_spring_length:
        state = initialize_resting_length(feet, state)
    solutions, seconds = [], []
    for k, (task, terms) in enumerate(zip(settings.tasks, terms_per_task), start=1):
        start = time.perf_counter()
        built = build_task_problem(feet, state, task, terms, name=f"gcp_task_{k}")
        solution = solve_task(built, verbose=2 if verbose else 0, **solver_options(settings, max_iterations))
        if verbose:
            print(f"GCP task {k}: " + solution.summary())
        state = updated_state(state, solution, len(feet))
        solutions.append(solution)
        seconds.append(time.perf_counter() - start)
        if on_task is not None:
            on_task(_group_result(feet, state, solutions, seconds))
        if stop_unconverged and not solution.success:
            break
    return _group_result(feet, state, solutions, seconds)


def unconverged_tasks(groups: Sequence[GroupResult]) -> list[str]:
    """A description of each task whose solve did not converge."""
    out = []
    for g, group in enumerate(groups, start=1):
        where = f" of foot group {g}" if len(groups) > 1 else ""
        out += [f"GCP task {k}{where}: {solution.status} ({solution.iterations} evaluations)"
                for k, solution in enumerate(group.solutions, start=1) if not solution.success]
    return out


def _group_result(feet: list[FootInputs], state: GcpState, solutions: list[Solution],
                  seconds: list[float]) -> GroupResult:
    design = state.design()
    values = [foot_values(foot, design, i) for i, foot in enumerate(feet)]
    return GroupResult(feet, state, list(solutions), values, list(seconds))


def convergence_histories(groups: Sequence[GroupResult]) -> dict[str, ConvergenceHistory | None]:
    """Each task's iterates, named ``task_<k>`` (with several foot groups ``group_<g>_task_<k>``)."""
    histories = {}
    for g, group in enumerate(groups, start=1):
        prefix = f"group_{g}_" if len(groups) > 1 else ""
        histories.update({f"{prefix}task_{k}": s.history for k, s in enumerate(group.solutions, start=1)})
    return histories


def run_log(settings: GroundContactPersonalizationSettings, groups: Sequence[GroupResult],
            errors: dict[int, dict[str, float]], note: str | None = None) -> str:
    """The run's summary (the original's ``commandWindowOutput.txt``): each task's solver
    summary and time, the final properties and the error table (``note``: a line after the
    title)."""
    lines = [f"Ground Contact Personalization: {settings.settings_file}"] + ([note] if note else [])
    for g, group in enumerate(groups, start=1):
        feet = ", ".join(str(f.index) for f in group.feet)
        lines.append(f"group {g} (feet {feet}):")
        for k, (solution, seconds) in enumerate(zip(group.solutions, group.task_seconds), start=1):
            lines.append(f"task {k} ({seconds:.1f} s): " + solution.summary())
        s = group.state
        lines.append(f"resting spring length {s.resting_spring_length:.6g} m, damping factor {s.damping_factor:.6g} "
                     f"s/m, dynamic friction {s.dynamic_friction_coefficient:.6g}, viscous friction "
                     f"{s.viscous_friction_coefficient:.6g} s/m, spring constants {s.spring_constants.min():.6g}.."
                     f"{s.spring_constants.max():.6g} N/m ({s.spring_constants.size} springs)")
    lines.append(report.format_error_table({f"foot {k}": e for k, e in errors.items()}, "GCP RMS errors"))
    return "\n".join(lines)


def _read_osimx(path: Path | None) -> OsimxModel | None:
    return read_osimx(path) if path is not None else None


def load_feet(settings: GroundContactPersonalizationSettings, *, spring_locations: Path | None = None
              ) -> tuple[list[FootInputs], CasadiModel, Any, Any, OsimxModel | None]:
    """Every enabled foot's inputs, plus the model, motion, GRF table and input ``.osimx``."""
    model = load_model(settings.input_model_file)
    casadi_model = CasadiModel(model)
    motion = read_motion(settings.input_motion_file, model)
    centers = {c for s in settings.contact_surfaces for c in s.electrical_center_columns}
    grf = read_ground_reactions(settings.input_grf_file, centers)
    osimx = _read_osimx(settings.input_osimx_file)
    springs_from = _read_osimx(spring_locations) if spring_locations is not None else osimx
    source = spring_locations if spring_locations is not None else settings.input_osimx_file
    feet = [build_foot_inputs(i + 1, surface, settings, model, casadi_model, motion, grf, springs_from,
                              spring_source=source)
            for i, surface in enumerate(settings.contact_surfaces)]
    return feet, casadi_model, motion, grf, osimx


def run_settings(path: str | Path, *, results_directory: str | Path | None = None, feet: str = "separately",
                 spring_locations: str | Path | None = None, max_iterations: int | None = None,
                 update_motion: bool = True, verbose: bool = False,
                 keep_finished_on_stop: bool = True, accept_unconverged: bool = False) -> GcpRunResult:
    """Run GCP from a settings file (module docstring)."""
    start = time.perf_counter()
    if feet not in FEET_MODES:
        raise InputError(f"feet='{feet}'", expected="'together' or 'separately'")
    path = Path(path)
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(path))
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    inputs = [settings.input_model_file, settings.input_motion_file, settings.input_grf_file, path]
    if settings.input_osimx_file is not None:
        inputs.append(settings.input_osimx_file)
    results = ResultsDirectory(  # refuses a read-only folder or an input folder now
        settings.results_directory, inputs=inputs, record="gcp", settings_file=path,
        input_folders={"motion (<input_motion_file>)": Path(settings.input_motion_file).parent,
                       "ground reactions (<input_grf_file>)": Path(settings.input_grf_file).parent},
        input_roots={"<input_directory>": settings.input_directory})
    task_terms(settings)
    all_feet, casadi_model, motion, grf, osimx = load_feet(
        settings, spring_locations=Path(spring_locations) if spring_locations is not None else None)
    groups_inputs = [all_feet] if feet == "together" else [[f] for f in all_feet]
    announce("GCP", settings=path, model=settings.input_model_file, trials=[Path(settings.input_motion_file).name],
             problem=f"{len(all_feet)} foot/feet ({', '.join(f.surface.hindfoot_body for f in all_feet)}), "
                     f"{sum(f.springs.n_springs for f in all_feet)} springs, {all_feet[0].n_frames} frames, "
                     f"{len(settings.tasks)} task(s), feet {feet}")
    groups: list[GroupResult] = []
    latest: list[GroupResult] = []  # the group in progress, after its last finished task

    def remember(group: GroupResult) -> None:
        latest[:] = [group]

    try:
        for group in groups_inputs:
            latest.clear()
            groups.append(optimize_group(settings, group, max_iterations=max_iterations, verbose=verbose,
                                         on_task=remember, stop_unconverged=not accept_unconverged))
            if unconverged_tasks(groups) and not accept_unconverged:
                break
    except KeyboardInterrupt:
        finished = groups + latest
        if keep_finished_on_stop and len(finished) == len(groups_inputs):  # every foot has a finished task
            k = len(finished[-1].solutions)
            where = f" of foot group {len(finished)}" if len(groups_inputs) > 1 else ""
            _write(results, settings, finished, casadi_model, motion, grf, osimx, update_motion, stopped_after=k,
                   note=f"stopped during task {k + 1} of {len(settings.tasks)}{where}: results after task {k}"
                        + (" (earlier groups: all tasks)" if where else ""))
            print(f"nmsm: GCP stopped during task {k + 1}{where}; the results after task {k} are in "
                  f"{results.path / STOPPED_FOLDER.format(k=k)}", file=sys.stderr)
        raise
    failures = unconverged_tasks(groups)
    stamp = settle(results, path, failures, accept=accept_unconverged,
                   write=lambda folder: _write_files(folder, settings, groups, casadi_model, motion, grf, osimx,
                                                     update_motion, _errors(groups)),
                   diagnosis=lambda note: _diagnosis(note, settings, groups, len(groups_inputs)))
    errors = _write(results, settings, groups, casadi_model, motion, grf, osimx, update_motion, unconverged=stamp)
    results.copy_in(path)
    outcome = GcpRunResult(settings, groups, results.path, errors, time.perf_counter() - start)
    summarize("GCP", summary_lines(outcome))
    return outcome


def summary_lines(outcome: GcpRunResult) -> list[str]:
    """The console summary: each task's solver outcome, the force and moment RMS errors per
    foot (N, N·m) and the kinematic errors, the time."""
    lines = []
    for g, group in enumerate(outcome.groups, start=1):
        feet = ", ".join(f"foot {f.index}" for f in group.feet)
        for k, solution in enumerate(group.solutions, start=1):
            lines.append(f"{feet}, task {k}: {solution.status} after {solution.iterations} iterations, "
                         f"{solution.wall_time:.1f} s")
    for foot, errors in outcome.errors.items():
        forces = ", ".join(f"{label.split()[0]} {errors[label]:.3g}" for label in report.ROWS[:3])
        moments = ", ".join(f"{label.split()[0]} {errors[label]:.3g}" for label in report.ROWS[3:6])
        lines.append(f"foot {foot}: force RMS (N) {forces}; moment RMS (N·m) {moments}; translation "
                     f"{errors[report.ROWS[6]]:.3g} mm, rotation {errors[report.ROWS[7]]:.3g} deg, markers "
                     f"{errors[report.ROWS[8]]:.3g} mm")
    lines.append(f"total time {outcome.wall_time:.1f} s")
    return lines


def _write(results: ResultsDirectory, settings: GroundContactPersonalizationSettings, groups: list[GroupResult],
           casadi_model: CasadiModel, motion: Any, grf: Any, osimx: OsimxModel | None, update_motion: bool, *,
           stopped_after: int | None = None, note: str | None = None,
           unconverged: str | None = None) -> dict[int, dict[str, float]]:
    """Write the groups' results as one task (``stopped_after``: a stopped run's results
    after that task, :meth:`ResultsDirectory.stopped_task`; ``unconverged``: the stamp of
    accepted unconverged results); returns the error table."""
    errors = _errors(groups)
    task = results.task("gcp", unconverged=unconverged) if stopped_after is None else results.stopped_task(stopped_after)
    with task as stage:
        _write_files(stage, settings, groups, casadi_model, motion, grf, osimx, update_motion, errors, note)
    return errors


def _diagnosis(note: str, settings: GroundContactPersonalizationSettings, groups: Sequence[GroupResult],
               n_groups: int) -> str:
    """``diagnosis.txt`` of an unconverged run: hints, then the run's log."""
    solutions = [s for group in groups for s in group.solutions]
    hints = dict.fromkeys(h for s in solutions if not s.success for h in status_hints(s.status, "<max_iterations>"))
    text = run_log(settings, groups, _errors(groups))
    if len(solutions) < len(settings.tasks) * n_groups:
        text += "\nlater tasks or foot groups not run: they would start from this unconverged result"
    return diagnosis_text(note, list(hints), text)


def _errors(groups: Sequence[GroupResult]) -> dict[int, dict[str, float]]:
    return {foot.index: report.rms_errors(foot, values)
            for group in groups for foot, values in zip(group.feet, group.values)}


def _write_files(folder: Path, settings: GroundContactPersonalizationSettings, groups: list[GroupResult],
                 casadi_model: CasadiModel, motion: Any, grf: Any, osimx: OsimxModel | None, update_motion: bool,
                 errors: dict[int, dict[str, float]], note: str | None = None) -> None:
    """The result files and ``commandWindowOutput.txt`` of ``groups`` in ``folder``."""
    write_results(folder, settings, groups, casadi_model, motion, grf, osimx, errors, update_motion=update_motion)
    (folder / "commandWindowOutput.txt").write_text(run_log(settings, groups, errors, note), encoding="utf-8")
    write_convergence_table(folder / CONVERGENCE_TABLE, convergence_histories(groups))

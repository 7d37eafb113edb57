"""``nmsm run`` for TO, VO and DO settings files: :func:`run_settings`.

    from nmsm.tools.treatment.run import run_settings
    run = run_settings("TorqueTOSettingsV1.xml", results_directory="out/TO1")
    print(run.summary)

Options (keyword arguments) are the fields of
:class:`~nmsm.tools.treatment.tool.TreatmentOptions`: directory overrides
(``results_directory``, ``initial_guess_directory``, ``tracked_quantities_directory``,
``guess_directory``), IPOPT overrides (``max_iterations``, ``tolerance``, ``hessian``,
``linear_solver``, ``print_level``, ``ipopt_options``), ``parallel``, ``evaluate_only``
(return the cost of the starting point without solving) and ``write_results``.

Results are staged and moved into the results folder only when the solve succeeded. A
failed solve, or one stopped with Ctrl-C (which then propagates as ``KeyboardInterrupt``),
writes its last iterate and a diagnosis into ``<results>/last_iterate/``, moves
the results an earlier run wrote there for the same trial into ``<results>/superseded/``
(:meth:`~nmsm.core.results.ResultsDirectory.retire`) and raises
:class:`~nmsm.errors.SolverError`. The IPOPT log is removed from the results folder however
the run ends (a copy goes with the results or the last iterate). A results folder that is
one of the input folders (tracked quantities, initial guess, guess) is refused before
solving, and the input data files are never overwritten. A starting point that violates a
constraint by more than :data:`~nmsm.tools.treatment.diagnosis.FAR_FROM_CONSISTENT` (scaled
units) is reported with its worst constraint block, state or load and collocation point.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.backends.ipopt import jacobian_direction_options
from nmsm.core.console import announce, console_enabled, summarize
from nmsm.core.interrupts import SolveInterrupted
from nmsm.core.problem import Solution
from nmsm.core.results import SUPERSEDED, ResultsDirectory
from nmsm.core.unconverged import ACCEPT_OPTION, status_hints, unconverged_note, warn_accepted, write_last_iterate
from nmsm.errors import InputError, SolverError
from nmsm.tools.treatment.diagnosis import FAR_FROM_CONSISTENT, convergence_summary, worst_constraint
from nmsm.tools.treatment.outcome import TreatmentRun
from nmsm.tools.treatment.solution import TreatmentSolution
from nmsm.tools.treatment.summary import summary_lines
from nmsm.tools.treatment.tool import Prepared, TreatmentOptions, prepare


def load_settings(path: str | os.PathLike[str]) -> tuple[Any, Any]:
    """(tool settings, solver settings) of a TO/VO/DO settings file."""
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.solver import OptimalControlSolverSettings
    from nmsm.io.settings.treatment import (
        DesignOptimizationSettings,
        TrackingOptimizationSettings,
        VerificationOptimizationSettings,
    )
    from nmsm.tools.treatment.surrogate_folder import check_surrogate_data_folder

    classes = {
        "TrackingOptimizationTool": TrackingOptimizationSettings,
        "VerificationOptimizationTool": VerificationOptimizationSettings,
        "DesignOptimizationTool": DesignOptimizationSettings,
    }
    doc = read_settings_document(path)
    cls = classes.get(doc.tool)
    if cls is None:
        raise InputError(f"<{doc.tool}> is not a treatment optimization tool", file=path,
                         expected="<TrackingOptimizationTool>, <VerificationOptimizationTool> or <DesignOptimizationTool>")
    check_surrogate_data_folder(doc)
    settings = cls.from_document(doc)
    solver_doc = read_settings_document(settings.optimal_control_solver_settings_file)
    return settings, OptimalControlSolverSettings.from_document(solver_doc)


def _options(kwargs: dict[str, Any]) -> TreatmentOptions:
    fields = {f.name for f in attrs.fields(TreatmentOptions)}
    unknown = set(kwargs) - fields
    if unknown:
        raise TypeError(f"unknown run_settings options: {', '.join(sorted(unknown))} (valid: {', '.join(sorted(fields))})")
    values = dict(kwargs)
    for key in ("results_directory", "initial_guess_directory", "tracked_quantities_directory", "guess_directory"):
        if values.get(key) is not None:
            values[key] = Path(values[key])
    return TreatmentOptions(**values)


def objective_scaling_factor(options: TreatmentOptions, initial_cost: float) -> float | None:
    """IPOPT ``obj_scaling_factor`` for ``options.objective_scaling`` (see TreatmentOptions)."""
    mode = options.objective_scaling
    if isinstance(mode, (int, float)):
        return float(mode)
    if mode == "none":
        return None
    if mode != "initial":
        raise ValueError(f"objective_scaling must be 'initial', 'none' or a number, got {mode!r}")
    if not initial_cost > 0:
        return None
    return float(min(max(1.0 / initial_cost, 1e-6), 1e6))


#: IPOPT options that keep it near a starting point that is a previous solution: a small
#: barrier parameter and the start moved at most 1e-9 into the bounds' interior
WARM_START_OPTIONS = {"mu_init": 1e-6, "bound_push": 1e-9, "bound_frac": 1e-9, "slack_bound_push": 1e-9,
                      "slack_bound_frac": 1e-9}

#: added to :data:`WARM_START_OPTIONS` when that start satisfies every constraint: a smaller
#: barrier parameter and bound multipliers ``mu / slack`` in place of IPOPT's constant ones, so
#: the start's complementarity is ``mu`` and IPOPT stops where it starts if the start is
#: optimal (with constant multipliers, a variable away from its bounds keeps it iterating)
FEASIBLE_START_OPTIONS = {"mu_init": 1e-9, "bound_mult_init_method": "mu-based"}

#: largest constraint violation (scaled units, as :func:`worst_constraint`) of a start that
#: counts as satisfying every constraint
FEASIBLE_START = 1e-8


#: IPOPT options of Design Optimization: the adaptive barrier update, which reaches lower
#: design objectives than the monotone default on the tutorials' DO files (measurements:
#: docs/developing.md, Treatment).
DESIGN_OPTIONS = {"mu_strategy": "adaptive"}


def warm_start_wanted(prepared: Prepared, options: TreatmentOptions) -> bool:
    """``options.warm_start``, or by default: VO starting from a previous result."""
    if options.warm_start is not None:
        return bool(options.warm_start)
    return prepared.tool == "VO" and "states" in prepared.files.results


def _ipopt_kwargs(prepared: Prepared, options: TreatmentOptions, log: Path | None,
                  initial_cost: float = 1.0, start_violation: float = float("inf")) -> dict[str, Any]:
    """IPOPT's options of the run; ``start_violation``: the starting point's largest
    constraint violation (scaled units)."""
    plan = dict(prepared.plan.ipopt)
    extra = dict(options.ipopt_options)
    if warm_start_wanted(prepared, options):
        warm = WARM_START_OPTIONS | (FEASIBLE_START_OPTIONS if start_violation <= FEASIBLE_START else {})
        for key, value in warm.items():
            extra.setdefault(key, value)
    if prepared.tool == "DO":
        for key, value in DESIGN_OPTIONS.items():
            extra.setdefault(key, value)
    factor = objective_scaling_factor(options, initial_cost)
    if factor is not None:
        extra.setdefault("obj_scaling_factor", factor)
    if log is not None:
        extra.setdefault("output_file", str(log))
        extra.setdefault("file_print_level", 5)
    return {
        "max_iter": options.max_iterations or plan["max_iter"],
        "tol": options.tolerance or plan["tol"],
        "linear_solver": options.linear_solver or plan["linear_solver"],
        "print_level": plan["print_level"] if options.print_level is None else options.print_level,
        "hessian": options.hessian or plan.get("hessian", "exact"),
        "ipopt_options": extra,
    }


def _input_files(prepared: Prepared) -> list[Path]:
    """Every data file the problem was built from (never to be overwritten by results)."""
    f = prepared.files
    tables = [f.tracked_ik, f.tracked_id, f.tracked_grf, f.initial_ik, f.initial_id, f.synergy_weights,
              *f.results.values()]
    return [Path(t.source) for t in tables if t is not None and getattr(t, "source", None)]


def _check_results_apart(settings: Any, options: TreatmentOptions, prepared: Prepared) -> None:
    """Refuse, before solving, a results folder that is, or is inside, one of the input folders."""
    path = Path(options.results_directory or settings.results_directory).resolve()
    inputs = {"tracked quantities": prepared.files.tracked_directory,
              "initial guess": prepared.files.initial_directory}
    if options.guess_directory is not None:
        inputs["guess"] = options.guess_directory
    for what, folder in inputs.items():
        folder = Path(folder).resolve()
        if path == folder or path.is_relative_to(folder):
            element = "<results_directory>" if options.results_directory is None else None
            where = "is" if path == folder else "is inside"
            raise InputError(f"the results folder {path} {where} the {what} folder {folder}: the results would mix "
                             "with the files they are computed from", file=settings.settings_file, element=element,
                             expected="a results folder apart from the input folders (e.g. results_directory=...)")


def _results_directory(settings: Any, options: TreatmentOptions, inputs: list[Path]) -> ResultsDirectory:
    """The run's results folder, recorded under the trial name: a rerun moves the earlier
    run's files of the trial into ``superseded/``, and a file it replaces that no run of the
    trial wrote (e.g. the original tool's results in a tutorial folder) into
    ``superseded/replaced/``, with a warning (:mod:`nmsm.core.results`)."""
    path = Path(options.results_directory or settings.results_directory)
    try:
        return ResultsDirectory(path, inputs=inputs, record=settings.trial_name,
                                settings_file=settings.settings_file)
    except OSError as exc:
        raise InputError(f"cannot create the results folder {path}: {exc.strerror or exc}",
                         file=settings.settings_file, element="<results_directory>",
                         expected="a writable folder (pass results_directory= to write elsewhere)") from exc


def run_settings(path: str | os.PathLike[str], **options: Any) -> TreatmentRun:
    """Run the TO, VO or DO settings file ``path`` (see module docstring)."""
    opts = _options(options)
    settings, solver_settings = load_settings(path)
    start = time.perf_counter()
    declare_extra = None
    if settings.tool_code == "DO":
        from nmsm.tools.treatment.design import design_extras

        declare_extra = design_extras(settings)
    prepared = prepare(settings, solver_settings, opts, declare_extra=declare_extra)
    build_time = time.perf_counter() - start
    problem = prepared.built.problem
    x0 = problem.initial_scaled()
    lo, hi = problem.bounds_scaled()
    import numpy as np

    x0 = np.clip(x0, lo, hi)
    initial_cost = float(np.asarray(problem.evaluate(problem.objective(), x0)).ravel()[0])
    worst = worst_constraint(prepared.built, x0)
    if worst is not None and worst.violation > FAR_FROM_CONSISTENT:
        message = f"{settings.settings_file}: {worst.message()}"
        warnings.warn(message, stacklevel=2)
        prepared.warnings.append(message)
    trial = settings.trial_name
    constraint_rows = sum(int(np.size(c.lower)) for c in problem.constraints)
    announce(prepared.tool, settings=path, model=settings.input_model_file, trials=[trial],
             problem=f"{prepared.plan.mesh.n_intervals} mesh intervals, {problem.n_variables} variables, "
                     f"{constraint_rows} constraint rows, {len(problem.costs)} cost terms")
    if opts.evaluate_only:
        solution = Solution(problem.unpack(x0), initial_cost, problem.term_costs(x0), False, "not solved (evaluate_only)",
                            0, 0.0, "none", x0, problem.constraint_report(x0))
        tsol = TreatmentSolution(prepared.built, solution, trial)
        return TreatmentRun(prepared, solution, tsol, convergence_summary(prepared.built, solution), initial_cost,
                            None, [], build_time)
    results = None
    if opts.write_results:
        _check_results_apart(settings, opts, prepared)
        results = _results_directory(settings, opts, [Path(path), Path(settings.input_model_file),
                                                      *_input_files(prepared)])
    # the IPOPT log is written into a hidden folder of this run, removed however the run ends
    log_dir = Path(tempfile.mkdtemp(prefix=".ipopt-", dir=results.ensure())) if results is not None else None
    try:
        start_violation = 0.0 if worst is None else worst.violation
        run = _solve_and_write(path, settings, prepared, opts, results, log_dir, initial_cost, build_time,
                               start_violation)
        if console_enabled():
            summarize(prepared.tool, summary_lines(run, problem.term_costs(x0)))
        return run
    finally:
        if log_dir is not None:
            shutil.rmtree(log_dir, ignore_errors=True)
        if results is not None:  # a stop or failure before any result leaves no empty folder
            results.remove_if_unused()


def _not_finite(solution: Solution) -> str:
    """``; not finite at the last iterate: ...`` naming the cost terms and constraint blocks
    whose value is NaN or infinite there (a term's bug or a pose outside its domain), else ``""``."""
    names = [name for name, value in solution.term_costs.items() if not np.isfinite(value)]
    names += [c.name for c in solution.constraints if not np.isfinite(c.max_violation)]
    if not names:
        return ""
    return f"; not finite at the last iterate: {', '.join(names[:6])}" + (" ..." if len(names) > 6 else "")


def _solve_and_write(path: str | os.PathLike[str], settings: Any, prepared: Prepared, opts: TreatmentOptions,
                     results: ResultsDirectory | None, log_dir: Path | None, initial_cost: float,
                     build_time: float, start_violation: float = float("inf")) -> TreatmentRun:
    """Solve; write the results (recorded under the trial name), or on failure the last
    iterate, after moving the earlier run's results of the trial into ``superseded/``."""
    trial = settings.trial_name
    log = log_dir / f"{trial}_ipopt.log" if log_dir is not None else None
    try:
        problem = prepared.built.problem
        solution = problem.solve("ipopt", casadi_options=jacobian_direction_options(problem),
                                 **_ipopt_kwargs(prepared, opts, log, initial_cost, start_violation))
    except SolveInterrupted as stop:
        if results is not None and stop.solution is not None:
            saved = _write_stopped(prepared, stop.solution, trial, results, log)
            print(f"nmsm: {settings.settings_file}: stopped after {stop.solution.iterations} iterations; the last "
                  f"iterate and a diagnosis are in {saved}", file=sys.stderr)
        raise
    tsol = TreatmentSolution(prepared.built, solution, trial)
    summary = convergence_summary(prepared.built, solution)
    files: list[Path] = []
    stamp = None
    if not solution.success:
        failure = f"IPOPT did not converge ({solution.status} after {solution.iterations} iterations)"
        if not opts.accept_unconverged:
            _keep_last_iterate(settings, prepared, solution, tsol, summary, results, log, failure)
        stamp = unconverged_note([failure])
        warn_accepted(settings.settings_file, stamp)
    if results is not None:
        from nmsm.tools.treatment.design import parameter_tables, write_parameter_solution
        from nmsm.tools.treatment.outputs import write_solution

        with results.task(trial, unconverged=stamp) as stage:
            files = write_solution(stage, tsol, summary=summary, extra_tables=parameter_tables(prepared, tsol))
            files += write_parameter_solution(stage, prepared, tsol)
            if (Path(results.path) / Path(path).name).resolve() != Path(path).resolve():  # not the settings itself
                shutil.copy2(path, stage / Path(path).name)
            if log is not None and log.is_file():
                shutil.copy2(log, stage / log.name)
        files = [Path(results.path) / f.relative_to(stage) for f in files]
    return TreatmentRun(prepared, solution, tsol, summary, initial_cost, Path(results.path) if results else None,
                        files, build_time)


def _keep_last_iterate(settings: Any, prepared: Prepared, solution: Solution, tsol: TreatmentSolution, summary: str,
                       results: ResultsDirectory | None, log: Path | None, failure: str) -> None:
    """The unconverged-result policy (:mod:`nmsm.core.unconverged`): the earlier run's results
    of the trial into ``superseded/``, the last iterate and the diagnosis into
    ``<results>/last_iterate/``; raises :class:`SolverError`."""
    trial = settings.trial_name
    saved, note = None, ""
    if results is not None:
        from nmsm.tools.treatment.outputs import write_solution

        if results.retire(trial):
            note = (f"; the results an earlier run wrote for trial '{trial}' were moved to "
                    f"{Path(results.path) / SUPERSEDED}")

        def write(folder: Path) -> None:
            write_solution(folder, tsol, summary=summary)
            if log is not None and log.is_file():
                shutil.copy2(log, folder / log.name)

        saved = write_last_iterate(results, write, _diagnosis(prepared, solution, summary),
                                   unconverged_note([failure]))
    raise SolverError(f"{settings.settings_file}: {failure}{_not_finite(solution)}{note}; {ACCEPT_OPTION} writes "
                      "the results anyway, stamped as unconverged",
                      last_iterate_path=str(saved) if saved is not None else None)


def _write_stopped(prepared: Prepared, solution: Solution, trial: str, results: ResultsDirectory,
                   log: Path | None) -> Path:
    """A solve stopped with Ctrl-C: its last iterate and the diagnosis into
    ``<results>/last_iterate/`` (the trial's earlier results stay where they are); returns
    that folder."""
    from nmsm.tools.treatment.outputs import write_solution

    tsol = TreatmentSolution(prepared.built, solution, trial)
    summary = convergence_summary(prepared.built, solution)

    def write(folder: Path) -> None:
        write_solution(folder, tsol, summary=summary)
        if log is not None and log.is_file():
            shutil.copy2(log, folder / log.name)

    return write_last_iterate(results, write, _diagnosis(prepared, solution, summary),
                              unconverged_note([f"was stopped (Ctrl-C) after {solution.iterations} iterations"]))


def _diagnosis(prepared: Prepared, solution: Solution, summary: str) -> str:
    hints = status_hints(solution.status, "<setup_nlp_max_iterations>")
    if solution.status == "Stopped_By_SIGINT":
        hints.insert(0, "The run was stopped (Ctrl-C) before IPOPT converged: this is the last iterate it reached, "
                        "not a result.")
    if prepared.warnings:
        hints.append("Input warnings:\n  " + "\n  ".join(prepared.warnings))
    return "Diagnosis\n=========\n" + ("\n".join(hints) + "\n\n" if hints else "") + summary + "\n"

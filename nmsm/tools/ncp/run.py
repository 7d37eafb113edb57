"""``nmsm run`` for ``<NeuralControlPersonalizationTool>``: read, optimize, write.

:func:`run_settings` reads the settings (older schemas upgraded), loads the model and
data (:mod:`nmsm.tools.ncp.loading`; MTLI first when enabled), builds the problem
(:mod:`nmsm.tools.ncp.problem`) from the NMF start (:mod:`nmsm.tools.ncp.initial_guess`),
solves it with IPOPT (exact gradient and Hessian, :mod:`nmsm.tools.ncp.hessian`),
normalizes the synergies (largest weight one) and writes the results
(:mod:`nmsm.tools.ncp.outputs`) through a staging folder, together with a copy of the
settings file, ``commandWindowOutput.txt`` (solver summary, costs, fit metrics) and
``ncpRunInfo.json`` (inputs used, for the figures that :func:`nmsm.plots.ncp.plot_ncp_results`
draws afterwards: ``nmsm plot RESULTS``, ``nmsm.run(..., plots=True)``).

Solver settings: the settings' ``max_iterations`` is IPOPT's ``max_iter``; IPOPT ``tol``
1e-8 (the fmincon tolerances of the settings file do not translate and are not used).
"""

from __future__ import annotations

import os
import shutil
import stat
import time
import warnings
from pathlib import Path
from typing import Any

import attrs

from nmsm.core.convergence import CONVERGENCE_TABLE, write_convergence_table
from nmsm.core.console import announce, summarize
from nmsm.core.problem import Solution
from nmsm.core.results import ResultsDirectory
from nmsm.core.unconverged import LAST_ITERATE, diagnosis_text, settle, status_hints
from nmsm.errors import InputError
from nmsm.io.layout import trial_table_folders
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.ncp import NeuralControlPersonalizationSettings
from nmsm.tools.ncp.initial_guess import initial_guess
from nmsm.tools.ncp.loading import NcpSetup, load_ncp
from nmsm.tools.ncp.metrics import FitMetrics, fit_metrics
from nmsm.tools.ncp.outputs import (
    RUN_INFO_FILE,
    WEIGHTS_FILE,
    ncp_osimx,
    osimx_file_name,
    relative_model_path,
    write_ncp_osimx,
    write_synergy_weights,
    write_run_info,
    write_trial_files,
)
from nmsm.tools.ncp.problem import PROXIMAL_WEIGHT, build_problem, score
from nmsm.tools.ncp.solution import SynergySolution

#: log written into the results folder, as the original's
LOG_FILE = "commandWindowOutput.txt"


@attrs.frozen(eq=False)
class NcpRun:
    """What a run produced: normalized synergies, solver result, costs, fit metrics, files."""

    setup: NcpSetup
    solution: SynergySolution
    solver: Solution
    costs: dict[str, float]
    metrics: FitMetrics
    results_directory: Path
    osimx_file: Path
    wall_time: float


def read_settings(path: str | os.PathLike[str]) -> NeuralControlPersonalizationSettings:
    """Validated NCP settings of ``path`` (older schemas upgraded with a warning)."""
    return NeuralControlPersonalizationSettings.from_document(read_settings_document(path))


#: IPOPT's acceptable-level stop: the objective unchanged to this relative amount over
#: ``acceptable_iter`` iterations with the scaled NLP error below ``acceptable_tol``. When a
#: group has more synergies than its activations need, equal-cost factorizations form
#: flat directions, and IPOPT's dual infeasibility then wanders (1e-7..1e-4) at a constant
#: objective instead of reaching ``tol`` (docs/developing.md, "NCP: measurements", "Stopping").
ACCEPTABLE_STOP = {"acceptable_tol": 1e-4, "acceptable_obj_change_tol": 1e-10, "acceptable_iter": 10}


def _ipopt_options(settings: NeuralControlPersonalizationSettings, overrides: dict[str, Any]) -> dict[str, Any]:
    options: dict[str, Any] = {
        "max_iter": int(settings.max_iterations),
        "tol": 1e-8,
        "acceptable_tol": ACCEPTABLE_STOP["acceptable_tol"],
        "print_level": 5,
    }
    given = {k: v for k, v in overrides.items() if v is not None}
    extra = {k: v for k, v in ACCEPTABLE_STOP.items() if k != "acceptable_tol"}
    options["ipopt_options"] = {**extra, **(given.pop("ipopt_options", None) or {})}
    options.update(given)
    return options


def solve(setup: NcpSetup, *, proximal_weight: float = PROXIMAL_WEIGHT, **ipopt_options: Any) -> tuple[SynergySolution, Solution]:
    """Optimize the synergies of ``setup``; returns the (not normalized) solution and the solver result.

    ``proximal_weight``: see :mod:`nmsm.tools.ncp.problem`; other options go to the IPOPT back end.
    """
    guess = initial_guess(setup.inputs)
    built = build_problem(setup.inputs, setup.terms, guess, proximal_weight=proximal_weight)
    structured = built.ipopt_options()
    options = {**structured, **ipopt_options}
    if "casadi_options" in ipopt_options and "casadi_options" in structured:
        options["casadi_options"] = {**structured["casadi_options"], **ipopt_options["casadi_options"]}
    solved = built.problem.solve("ipopt", **options)
    if "Acceptable" in solved.status:
        warnings.warn(f"NCP: IPOPT stopped at its acceptable level after {solved.iterations} iterations (objective "
                      f"unchanged to {ACCEPTABLE_STOP['acceptable_obj_change_tol']:g} over "
                      f"{ACCEPTABLE_STOP['acceptable_iter']} iterations, tolerance {ipopt_options.get('tol', 1e-8):g} not "
                      "reached: equal-cost synergy factorizations leave flat directions)", stacklevel=2)
    return built.solution(solved), solved


def converged(solved: Solution) -> bool:
    """Whether IPOPT reached its tolerance or its acceptable level (:data:`ACCEPTABLE_STOP`)."""
    return bool(solved.success) or "Acceptable" in solved.status


def _log_text(setup: NcpSetup, solved: Solution, costs: dict[str, float], metrics: FitMetrics, wall: float) -> str:
    inputs = setup.inputs
    lines = [
        f"Neural Control Personalization: {setup.settings.settings_file}",
        f"model {setup.settings.input_model_file}; {inputs.layout.n_muscles} muscles, "
        f"{inputs.layout.n_synergies} synergies "
        + ", ".join(f"{g.name}: {g.n_synergies} of {g.n_muscles} muscles" for g in inputs.layout.groups),
        f"bilateral symmetry (shared vectors): {'yes' if any(s is not None for s in inputs.layout.shared_from) else 'no'}",
        f"trials: {', '.join(t.name for t in inputs.trials)}; muscles with MTP activations: {len(inputs.mtp_muscles)}",
        "muscles without MTP activations (driven by the moments only): "
        + (", ".join(inputs.layout.muscles[i] for i in inputs.other_indices) or "none"),
        solved.summary(),
        "cost terms at the solution:",
        *[f"  {k:<40s} {v:.8g}" for k, v in costs.items()],
        "moment RMS (N m) per coordinate:",
        *[f"  {c:<40s} {v:.4f}" for c, v in zip(metrics.coordinates, metrics.moment_rms)],
        f"  mean over coordinates                    {metrics.mean_moment_rms:.4f}",
        (f"activation RMS vs MTP (pooled): {metrics.activation_rms_pooled:.5f}; VAF {100 * metrics.activation_vaf:.2f} %"
         if inputs.mtp_muscles else "activation RMS vs MTP: none (no muscle has MTP activations)"),
        f"wall time {wall:.1f} s",
    ]
    if setup.mtli_muscles:
        lines.append("muscle-tendon length initialization updated: " + ", ".join(setup.mtli_muscles))
    if setup.dropped_coordinates:
        lines.append("coordinates without ID data (not tracked): " + ", ".join(setup.dropped_coordinates))
    return "\n".join(lines) + "\n"


def summary_lines(solved: Solution, metrics: FitMetrics, wall: float) -> list[str]:
    """The console summary: IPOPT's outcome, the moment RMS per coordinate (N·m), the
    activation RMS and VAF against MTP's activations, the time."""
    lines = [f"IPOPT {solved.status} after {solved.iterations} iterations, {solved.wall_time:.1f} s; cost "
             f"{solved.cost:.6g}", "joint moment RMS error (N·m):"]
    lines += [f"  {c:<32s} {v:8.3f}" for c, v in zip(metrics.coordinates, metrics.moment_rms)]
    if metrics.mtp_muscles:
        lines.append(f"activation RMS vs MTP {metrics.activation_rms_pooled:.4f} ({len(metrics.mtp_muscles)} muscles, "
                     f"pooled); VAF {100 * metrics.activation_vaf:.2f} %")
    else:
        lines.append("activation RMS vs MTP: none (no muscle has MTP activations)")
    lines.append(f"total time {wall:.1f} s")
    return lines


def _check_writable(folder: Path, settings_file: Path) -> None:
    """Fail before optimizing when the results folder cannot (or must not) be written.

    A folder without any write permission bit counts as read-only even for a user who
    could override it (root): input data folders are marked that way.
    """
    existing = folder
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    marked_read_only = stat.S_IMODE(existing.stat().st_mode) & 0o222 == 0
    if marked_read_only or not os.access(existing, os.W_OK):
        raise InputError(
            f"results folder {folder} cannot be written ({existing} is read-only)",
            file=settings_file,
            element="<results_directory>",
            expected="a writable folder (or pass results_directory=... / another settings file)",
        )


def run_settings(
    path: str | os.PathLike[str],
    *,
    results_directory: str | os.PathLike[str] | None = None,
    enforce_bilateral_symmetry: bool | None = None,
    max_iterations: int | None = None,
    tolerance: float | None = None,
    print_level: int | None = None,
    proximal_weight: float = PROXIMAL_WEIGHT,
    accept_unconverged: bool = False,
    **ipopt: Any,
) -> NcpRun:
    """Run NCP as the settings file ``path`` says.

    Options override the settings: ``results_directory``, ``enforce_bilateral_symmetry``,
    ``max_iterations``, ``tolerance`` (IPOPT ``tol``), ``print_level`` (IPOPT output, 0 quiet),
    ``proximal_weight`` (pull toward the start where the terms leave activations free, see
    :mod:`nmsm.tools.ncp.problem`); other keyword arguments go to the IPOPT back end.
    A solve that did not converge writes its last iterate into ``<results>/last_iterate/``
    and raises :class:`~nmsm.errors.SolverError` unless ``accept_unconverged`` (:mod:`nmsm.core.unconverged`).
    """
    start = time.perf_counter()
    settings = read_settings(path)
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    _check_writable(Path(settings.results_directory), settings.settings_file)
    setup = load_ncp(settings, enforce_bilateral_symmetry=enforce_bilateral_symmetry)
    out_dir = Path(settings.results_directory)
    inputs_used = [settings.input_model_file, settings.settings_file]
    if setup.osimx_file is not None:
        inputs_used.append(setup.osimx_file)
    roots = {"<data_directory>": settings.data_directory}
    if settings.mtp_results_directory is not None:
        roots["<mtp_results_directory>"] = settings.mtp_results_directory
    results = ResultsDirectory(out_dir, inputs=[p for p in inputs_used if p],
                               input_folders=trial_table_folders(settings.data_directory, "<data_directory>"),
                               input_roots=roots, record="ncp", settings_file=settings.settings_file)
    options = _ipopt_options(settings, {"max_iter": max_iterations, "tol": tolerance, "print_level": print_level, **ipopt})
    layout = setup.inputs.layout
    announce("NCP", settings=settings.settings_file, model=settings.input_model_file,
             trials=[t.name for t in setup.inputs.trials],
             problem=f"{layout.n_muscles} muscles, {layout.n_synergies} synergies in {len(layout.groups)} group(s), "
                     f"{len(setup.inputs.mtp_muscles)} muscles with MTP activations")
    raw, solved = solve(setup, proximal_weight=proximal_weight, **options)
    solution = raw.normalized()
    costs = score(setup.inputs, setup.terms, solution)
    metrics = fit_metrics(setup.inputs, solution)
    osimx_name = osimx_file_name(setup.osimx_file, settings.input_model_file)
    wall = time.perf_counter() - start

    def write(folder: Path) -> None:
        write_synergy_weights(folder / WEIGHTS_FILE, solution)
        write_trial_files(folder, setup.inputs, solution)
        osimx = ncp_osimx(
            setup.osimx,
            setup.model.name,
            relative_model_path(Path(settings.input_model_file), out_dir / LAST_ITERATE if folder.name == LAST_ITERATE
                                else out_dir),
            setup.inputs,
            mtli_muscles=setup.mtli_muscles,
            updated_max_isometric_force=setup.mtli_muscles if setup.mtli_updated_force else (),
        )
        write_ncp_osimx(folder / osimx_name, osimx)
        write_run_info(folder / RUN_INFO_FILE, setup)
        (folder / LOG_FILE).write_text(_log_text(setup, solved, costs, metrics, wall), encoding="utf-8")
        write_convergence_table(folder / CONVERGENCE_TABLE, {"ncp": solved.history})

    failures = [] if converged(solved) else [f"NCP: IPOPT {solved.status} after {solved.iterations} iterations"]
    stamp = settle(results, settings.settings_file, failures, accept=accept_unconverged, write=write,
                   diagnosis=lambda note: diagnosis_text(note, status_hints(solved.status, "<max_iterations>"),
                                                         _log_text(setup, solved, costs, metrics, wall)))
    with results.task("ncp", unconverged=stamp) as stage:
        write(stage)
        settings_copy = out_dir / Path(settings.settings_file).name
        if settings_copy.resolve() != Path(settings.settings_file).resolve():
            shutil.copy2(settings.settings_file, stage / settings_copy.name)
    summarize("NCP", summary_lines(solved, metrics, wall))
    return NcpRun(
        setup=setup,
        solution=solution,
        solver=solved,
        costs=costs,
        metrics=metrics,
        results_directory=out_dir,
        osimx_file=out_dir / osimx_name,
        wall_time=time.perf_counter() - start,
    )

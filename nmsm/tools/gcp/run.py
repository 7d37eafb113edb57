"""Ground Contact Personalization from a settings file: ``run_settings(path, **options)``
(``nmsm run`` dispatches ``<GroundContactPersonalizationTool>`` here).

Steps: read the settings (old schemas upgraded), the model, motion and ground reactions;
build each enabled foot (two-segment foot model, springs, experimental kinematics and
reactions on its window); optionally initialize the resting spring length; run the enabled
tasks in index order, each starting from the previous solution; write the results
(:mod:`nmsm.tools.gcp.outputs`) through a staged results folder and copy the settings file
there.

Options:

``results_directory``  override the settings' results folder (e.g. when it is read-only);
``feet``               ``"together"`` (default, as the original: the feet share spring
                       constants, damping, friction and resting length) or ``"separately"``
                       (one problem per foot, each with its own properties);
``spring_locations``   an ``.osimx`` whose contact surfaces give the spring bodies and
                       locations (default: the settings' ``input_osimx_file`` when it has a
                       surface on the foot's hindfoot, else the marker-based grid of
                       :mod:`nmsm.tools.gcp.spring_grid`);
``max_iterations``     override the settings' iteration limit of every task;
``update_motion``      re-run IK with the modeled foot markers (default True);
``verbose``            print each solver iteration.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.problem import Solution
from nmsm.core.results import ResultsDirectory
from nmsm.core.term import build_terms
from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel, read_osimx, write_osimx
from nmsm.io.settings.document import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.io.storage import write_storage
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.osim import load_model
from nmsm.tools.gcp import outputs, report
from nmsm.tools.gcp.data import full_coordinates, read_ground_reactions, read_motion
from nmsm.tools.gcp.ik_update import updated_motion
from nmsm.tools.gcp.inputs import FootInputs, build_foot_inputs, check_equal_spring_counts
from nmsm.tools.gcp.problem import build_task_problem, solver_options, updated_state
from nmsm.tools.gcp.rest_length import initialize_resting_length
from nmsm.tools.gcp.state import GcpState
from nmsm.tools.gcp.values import FootValues, as_array, foot_values
from nmsm.tools.jmp.ik import motion_table

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


def optimize_group(settings: GroundContactPersonalizationSettings, feet: list[FootInputs], *,
                   max_iterations: int | None = None, verbose: bool = False) -> GroupResult:
    """Initialize and run every task for ``feet`` optimized together."""
    check_equal_spring_counts(feet, settings.settings_file)
    state = GcpState.initial(settings, feet)
    if settings.initialize_resting_spring_length:
        state = initialize_resting_length(feet, state)
    solutions, seconds = [], []
    for k, task in enumerate(settings.tasks, start=1):
        start = time.perf_counter()
        terms = build_terms(list(task.cost_terms), "GCP")
        if not terms:
            raise InputError(f"GCP task {task.index or k} has no enabled cost term", file=settings.settings_file,
                             line=task.source.line, element="<RCNLCostTermSet>", expected="at least one enabled term")
        if not any(task.design_flags.values()):
            raise InputError(f"GCP task {task.index or k} optimizes nothing", file=settings.settings_file,
                             line=task.source.line, element="<GCPTask>", expected="at least one design flag true")
        built = build_task_problem(feet, state, task, terms, name=f"gcp_task_{k}")
        solution = built.problem.solve("least_squares", verbose=2 if verbose else 0,
                                       **solver_options(settings, max_iterations))
        if verbose:
            print(f"GCP task {k}: " + solution.summary())
        state = updated_state(state, solution, len(feet))
        solutions.append(solution)
        seconds.append(time.perf_counter() - start)
    design = state.design()
    values = [foot_values(foot, design, i) for i, foot in enumerate(feet)]
    return GroupResult(feet, state, solutions, values, seconds)


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


def run_settings(path: str | Path, *, results_directory: str | Path | None = None, feet: str = "together",
                 spring_locations: str | Path | None = None, max_iterations: int | None = None,
                 update_motion: bool = True, verbose: bool = False) -> GcpRunResult:
    """Run GCP from a settings file (module docstring)."""
    start = time.perf_counter()
    if feet not in FEET_MODES:
        raise InputError(f"feet='{feet}'", expected="'together' or 'separately'")
    path = Path(path)
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(path))
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    all_feet, casadi_model, motion, grf, osimx = load_feet(
        settings, spring_locations=Path(spring_locations) if spring_locations is not None else None)
    groups_inputs = [all_feet] if feet == "together" else [[f] for f in all_feet]
    groups = [optimize_group(settings, group, max_iterations=max_iterations, verbose=verbose)
              for group in groups_inputs]
    errors = {foot.index: report.rms_errors(foot, values)
              for group in groups for foot, values in zip(group.feet, group.values)}
    inputs = [settings.input_model_file, settings.input_motion_file, settings.input_grf_file, path]
    if settings.input_osimx_file is not None:
        inputs.append(settings.input_osimx_file)
    results = ResultsDirectory(settings.results_directory, inputs=inputs)
    with results.task("gcp") as stage:
        write_results(stage, settings, groups, casadi_model, motion, grf, osimx, errors, update_motion=update_motion)
    results.copy_in(path)
    return GcpRunResult(settings, groups, results.path, errors, time.perf_counter() - start)


@attrs.frozen(eq=False)
class FootResult:
    """One foot's inputs, final values and the state of its group (``slot``: its position
    in that group)."""

    foot: FootInputs
    values: FootValues
    state: GcpState
    slot: int

    @property
    def correction(self) -> outputs.PlateCorrection:
        return outputs.PlateCorrection(self.state.electrical_center_shifts[self.slot],
                                       self.state.plate_rotations[self.slot], self.state.resting_spring_length)


def foot_results(groups: Sequence[GroupResult]) -> list[FootResult]:
    return [FootResult(f, v, g.state, i) for g in groups for i, (f, v) in enumerate(zip(g.feet, g.values))]


def write_results(stage: Path, settings: GroundContactPersonalizationSettings, groups: Sequence[GroupResult],
                  casadi_model: CasadiModel, motion: Any, grf: Any, osimx: OsimxModel | None,
                  errors: dict[int, dict[str, float]], *, update_motion: bool) -> None:
    """Every result file of :mod:`nmsm.tools.gcp.outputs` into ``stage``."""
    prefix = settings.input_model_file.stem
    results = foot_results(groups)
    feet = [r.foot for r in results]
    values = [r.values for r in results]
    for r in results:
        outputs.write_foot_files(stage, prefix, r.foot, r.values, r.state)
    surfaces = [outputs.contact_surface(r.foot, r.state) for r in results]
    base_name = settings.input_osimx_file.stem if settings.input_osimx_file is not None else prefix
    document = outputs.osimx_model(osimx, casadi_model.model.name, str(settings.input_model_file), surfaces)
    write_osimx(stage / f"{base_name}_gcp.osimx", document)
    (stage / f"{prefix}_gcpErrors.txt").write_text(
        report.format_error_table({f"foot {k}": e for k, e in errors.items()}, "GCP RMS errors (nmsm)"))
    if not outputs.same_window(feet):
        warnings.warn("feet have different time windows: combined GRFData/IKData files are not written",
                      stacklevel=2)
        return
    grf_name = Path(settings.input_grf_file.name)
    (stage / "GRFData").mkdir(exist_ok=True)
    modeled, modeled_cop = outputs.modeled_grf_tables(feet, values, [r.state.resting_spring_length for r in results])
    write_storage(stage / "GRFData" / f"gcp_modeled_{grf_name}", modeled)
    write_storage(stage / "GRFData" / f"gcp_modeled_{grf_name.stem}_CoP{grf_name.suffix}", modeled_cop)
    if any(task.electricalCenterX or task.electricalCenterY or task.electricalCenterZ or task.forcePlateRotation
           for task in settings.tasks):
        adjusted, adjusted_cop = outputs.adjusted_grf_tables(grf, feet, [r.correction for r in results])
        write_storage(stage / "GRFData" / f"gcp_adjusted{grf_name}", adjusted)
        write_storage(stage / "GRFData" / f"gcp_adjusted{grf_name.stem}_CoP{grf_name.suffix}", adjusted_cop)
    if update_motion:
        write_updated_motion(stage, settings, casadi_model, motion, feet, values)


def write_updated_motion(stage: Path, settings: GroundContactPersonalizationSettings, casadi_model: CasadiModel,
                         motion: Any, feet: Sequence[FootInputs], values: Sequence[FootValues]) -> None:
    """``IKData/gcp_modeled_<motion>`` (:mod:`nmsm.tools.gcp.ik_update`)."""
    times = feet[0].time
    rows = np.array([int(np.argmin(np.abs(motion.time - t))) for t in times])
    q_full = full_coordinates(motion, casadi_model.model, rows, feet[0].foot.hindfoot_body,
                              motion_file=settings.input_motion_file)
    targets: dict[str, np.ndarray] = {}
    for foot, v in zip(feet, values):
        markers = as_array(v.markers).T.reshape(foot.n_frames, 5, 3)
        for k, name in enumerate(foot.foot.markers.names()):
            targets[name] = markers[:, k, :]
    result = updated_motion(casadi_model, times, q_full, targets)
    (stage / "IKData").mkdir(exist_ok=True)
    write_storage(stage / "IKData" / f"gcp_modeled_{settings.input_motion_file.name}", motion_table(result),
                  name="Coordinates")

"""One JMP task: design, inverse kinematics before, the joint solve, the new model, IK after.

:func:`run_task` takes the model the task starts from (the input model, or the previous
task's output: tasks are chained, each starting from the model the previous one wrote;
the original takes every task's initial values and bounds from the input model, which
only matters for a parameter optimized by two tasks) and writes the task's model to
``output``.

Inverse kinematics before and after use the task's markers with weight 1 and the
settings' ``accuracy``; "after" runs on the written ``.osim`` read back, so it checks the
file as well as the optimization.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import attrs
import numpy as np

from nmsm.core.registry import get_registry
from nmsm.io.settings.jmp import JmpTask
from nmsm.io.trc import read_trc
from nmsm.model.osim import load_model
from nmsm.tools.jmp.design import TaskDesign, build_design
from nmsm.tools.jmp.ik import IkResult, inverse_kinematics
from nmsm.core.backends.levenberg_marquardt import Tolerances
from nmsm.tools.jmp.marker_data import MarkerTrial, check_units, select_trial
from nmsm.tools.jmp.marker_model import MarkerKinematics
from nmsm.tools.jmp.model_output import write_task_model
from nmsm.tools.jmp.problem import JmpProblem, JmpSolution

#: joints whose coordinates move less than this over a task's trial get a warning (rad)
MIN_RANGE_OF_MOTION = np.radians(25.0)


@attrs.frozen(eq=False)
class TaskResult:
    """Outcome of one task (see module docstring); ``output`` is the model it wrote."""

    task: JmpTask
    label: str
    design: TaskDesign
    trial: MarkerTrial
    solution: JmpSolution
    before: IkResult
    after: IkResult
    output: Path
    notes: tuple[str, ...]

    @property
    def values(self) -> np.ndarray:
        return self.solution.p


def task_label(task: JmpTask, position: int) -> str:
    return f"Task {task.index if task.index is not None else position} '{task.name or 'unnamed'}'"


def _warn_small_motion(model_label: str, design: TaskDesign, task: JmpTask, before: IkResult,
                       settings_file: str | None) -> list[str]:
    notes = []
    model = design.parameters.model
    for joint in task.joints:
        coordinates = [c for c in model.joint(joint.name).coordinates
                       if c in before.free_names and model.coordinate(c).motion_type == "rotational"]
        if not coordinates:
            continue
        ranges = {c: float(np.ptp(before.coordinate(c))) for c in coordinates}
        if max(ranges.values()) < MIN_RANGE_OF_MOTION:
            text = (f"joint '{joint.name}' moves little in {task.marker_file_name.name} ("
                    + ", ".join(f"{c} {np.degrees(r):.1f} deg" for c, r in ranges.items())
                    + f" < {np.degrees(MIN_RANGE_OF_MOTION):.0f} deg): its parameters are unreliable")
            warnings.warn(f"{settings_file}: {model_label}: {text}", stacklevel=3)
            notes.append(text)
    return notes


#: rounds of re-seating frames in a better inverse-kinematics solution (see :func:`solve_reseating_frames`)
MAX_RESEATS = 5
#: a frame is re-seated when inverse kinematics lowers its cost by more than this fraction
RESEAT_GAIN = 1e-3
#: iterations of the joint solve between two searches for frames to re-seat
RESEAT_CHECK_ITERATIONS = 25


def _frames_to_reseat(problem: JmpProblem, model, trial: MarkerTrial, kinematics: MarkerKinematics,
                      design: TaskDesign, solution: JmpSolution,
                      ik_accuracy: float | None) -> tuple[np.ndarray, int] | None:
    """Start coordinates ``(F, n_free)`` and how many frames they re-seat: those of inverse
    kinematics with the solution's parameters where it fits a frame better than the
    solution's coordinates by more than :data:`RESEAT_GAIN`, the solution's elsewhere;
    ``None`` when no frame fits better."""
    ik = inverse_kinematics(model, trial, accuracy=ik_accuracy, kinematics=kinematics, parameters=design.parameters,
                            parameter_values=solution.p, check_marker_units=False)
    q_ik = ik.q[:, [ik.coordinate_names.index(n) for n in kinematics.free_names]]
    current = problem.frame_costs(solution.q, solution.p)
    better = problem.frame_costs(q_ik, solution.p) < (1.0 - RESEAT_GAIN) * current
    if not better.any():
        return None
    return np.where(better[:, None], q_ik, solution.q), int(better.sum())


def solve_reseating_frames(problem: JmpProblem, model, trial: MarkerTrial, kinematics: MarkerKinematics,
                           design: TaskDesign, q0: np.ndarray, p0: np.ndarray, tolerances: Tolerances,
                           ik_accuracy: float | None) -> JmpSolution:
    """Solve the task, re-seating frames whose coordinates sit in a worse local minimum than
    inverse kinematics finds with the current parameters.

    The joint problem moves every frame's coordinates by local steps from their start (the
    inverse kinematics of the input model): a frame that starts in another basin of its
    inverse kinematics (a knee at the end of its range, an arm turned the other way with its
    elbow on its limit) stays there and pulls the parameters with it, while JMP's objective is
    the marker error left by inverse kinematics of each parameter set. The solve runs in
    spans of :data:`RESEAT_CHECK_ITERATIONS` iterations; after each span and at convergence,
    inverse kinematics with the current parameters (frame after frame from the first) looks
    for such frames, which restart from its solution (at most :data:`MAX_RESEATS` rounds).
    Checking during the solve matters: with a frame in the wrong basin the iterations crawl
    along a valley of the marker error long before any stopping rule holds. The solve ends
    when it converges with no frame to re-seat, or at the iteration or evaluation limit.
    """
    iterations = evaluations = reseated = rounds = 0
    wall = 0.0
    initial_cost = history = None
    q, p = q0, p0
    while True:
        span = min(RESEAT_CHECK_ITERATIONS, tolerances.max_iterations - iterations)
        limits = attrs.evolve(tolerances, max_iterations=span, max_evaluations=tolerances.max_evaluations - evaluations)
        solution = problem.solve(q, p, limits)
        iterations += solution.iterations
        evaluations += solution.evaluations
        wall += solution.wall_time
        initial_cost = solution.initial_cost if initial_cost is None else initial_cost
        solution = attrs.evolve(solution, initial_cost=initial_cost, iterations=iterations, evaluations=evaluations,
                                wall_time=wall, reseated_frames=reseated,
                                history=history.followed_by(solution.history) if history is not None
                                else solution.history)
        history = solution.history
        spent = iterations >= tolerances.max_iterations or evaluations >= tolerances.max_evaluations
        if not solution.converged and solution.status != "maximum iterations reached":
            return solution
        found = None
        if rounds < MAX_RESEATS:
            found = _frames_to_reseat(problem, model, trial, kinematics, design, solution, ik_accuracy)
        if found is not None and not spent:
            (q, count), p = found, solution.p
            reseated += count
            rounds += 1
            continue
        if solution.converged or spent:
            return solution
        q, p = solution.q, solution.p


def run_task(model_file: Path, task: JmpTask, position: int, *, allowable_error: float, tolerances: Tolerances,
             ik_accuracy: float | None, output: Path, settings_file: str | None = None,
             log: Callable[[str], None] = print) -> TaskResult:
    """Run ``task`` on the model in ``model_file`` and write the personalized model to ``output``."""
    label = task_label(task, position)
    model = load_model(model_file)
    table = read_trc(task.marker_file_name)
    design = build_design(model, task, table.names, settings_file=settings_file)
    trial = select_trial(table, model, {m: 1.0 for m in design.marker_names}, time_range=task.time_range,
                         settings_file=settings_file)
    kinematics = MarkerKinematics(model, trial.names, design.parameters,
                                  unscaled_marker_bodies=design.unscaled_marker_bodies)
    p0 = design.initial
    q_default = kinematics.initial_free()
    trial, factor = check_units(trial, kinematics.marker_positions(q_default[None, :], p0)[0])
    log(f"{label}: {trial.n_markers} markers, {trial.n_frames} frames ({trial.time[0]:g}-{trial.time[-1]:g} s), "
        f"{kinematics.n_free} coordinates, {len(design.variables)} parameters")
    before = inverse_kinematics(model, trial, accuracy=ik_accuracy, kinematics=kinematics, parameters=design.parameters,
                                parameter_values=p0, check_marker_units=False)
    before = attrs.evolve(before, unit_factor=factor)
    notes = _warn_small_motion(label, design, task, before, settings_file)
    q0 = before.q[:, [before.coordinate_names.index(n) for n in kinematics.free_names]]
    term = get_registry().get("cost", "marker_distance_error", "JMP")(
        max_allowable_error=allowable_error, name=task.name, source=task.source)
    problem = JmpProblem(kinematics, trial, [term], design.lower, design.upper)
    solution = solve_reseating_frames(problem, model, trial, kinematics, design, q0, p0, tolerances, ik_accuracy)
    log(f"{label}: {solution.status} after {solution.iterations} iterations ({solution.wall_time:.1f} s); "
        f"cost {solution.initial_cost:.6g} -> {solution.cost:.6g}"
        + (f"; {solution.reseated_frames} frame(s) re-seated in their inverse kinematics" if solution.reseated_frames
           else ""))
    if not solution.converged:
        warnings.warn(f"{settings_file}: {label}: the optimization stopped before converging ({solution.status})",
                      stacklevel=2)
    notes += write_task_model(model, Path(model_file), design, solution.p, output,
                              anatomical_markers=task.anatomical_markers)
    written = load_model(output)
    after = inverse_kinematics(written, trial, accuracy=ik_accuracy, check_marker_units=False)
    log(f"{label}: marker RMS {1000 * before.marker_rms():.3f} -> {1000 * after.marker_rms():.3f} mm, "
        f"max {1000 * before.marker_max():.3f} -> {1000 * after.marker_max():.3f} mm")
    return TaskResult(task=task, label=label, design=design, trial=trial, solution=solution, before=before,
                      after=after, output=output, notes=tuple(notes))

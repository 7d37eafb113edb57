"""Inverse kinematics: weighted marker least squares, frame by frame, with exact Jacobians.

For each frame ``k`` the free coordinates ``q`` (see
:class:`~nmsm.tools.jmp.marker_model.MarkerKinematics`) minimize

    sum_m w_m |x_m(q) - x_m,exp(t_k)|^2  +  sum_c w_c (q_c - q_c,ref(t_k))^2

within the ranges of clamped coordinates, as OpenSim's InverseKinematicsSolver does with
``constraint_weight = Inf``: locked coordinates stay at their default values, coupled
coordinates follow their couplers, a marker missing in a frame (NaN) is dropped from that
frame. The first frame starts from the model's default pose (as OpenSim's ``assemble``)
and, when a clamped coordinate's default sits on a bound of its range, also from that pose
with such coordinates at mid-range; the lower cost wins (:func:`first_frame_starts`). Every
later frame starts from the previous solution. Each frame is a small bound-constrained
Levenberg-Marquardt solve (:mod:`~nmsm.core.backends.levenberg_marquardt`) on a CasADi SX
function giving residuals and their exact Jacobian.

Entry points: :func:`inverse_kinematics` (arrays in, :class:`IkResult` out),
:func:`run_ik_files` (model / .trc / IK settings paths, as ``nmsm ik``), and
:func:`motion_table` / :func:`write_motion` for OpenSim's ``.mot`` (degrees).
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage, write_storage
from nmsm.io.trc import MarkerTable, read_trc
from nmsm.model.components import Model
from nmsm.model.osim import load_model
from nmsm.model.parameters import ModelParameters
from nmsm.tools.jmp.dense_evaluator import DenseEvaluator
from nmsm.tools.jmp.ik_settings import CoordinateTask, IkSettings, read_ik_settings
from nmsm.core.backends.levenberg_marquardt import Tolerances, solve
from nmsm.core.jacobians import DenseJacobian
from nmsm.tools.jmp.marker_data import MarkerTrial, check_units, frames_in_range, select_trial
from nmsm.tools.jmp.marker_model import MarkerKinematics
from nmsm.io.motion_units import warn_implausible_angles

#: OpenSim's default IK accuracy
DEFAULT_ACCURACY = 1e-5


@attrs.frozen(eq=False)
class IkResult:
    """Inverse-kinematics solution.

    ``q (F, n)``: every model coordinate (model order), rad / m; ``marker_errors (F, M)``:
    distance (m) of each used marker from its experimental position, NaN in gaps;
    ``iterations (F,)`` and ``converged (F,)`` per frame; ``wall_time`` s (solve loop only).
    """

    time: np.ndarray
    coordinate_names: tuple[str, ...]
    q: np.ndarray
    marker_names: tuple[str, ...]
    marker_errors: np.ndarray
    weights: np.ndarray
    free_names: tuple[str, ...]
    locked_names: tuple[str, ...]
    insensitive_names: tuple[str, ...]
    rotational: frozenset[str]
    iterations: np.ndarray
    converged: np.ndarray
    wall_time: float
    unit_factor: float = 1.0

    @property
    def n_frames(self) -> int:
        return int(self.time.size)

    def coordinate(self, name: str) -> np.ndarray:
        """One coordinate over time ``(F,)`` (rad / m)."""
        return self.q[:, self.coordinate_names.index(name)]

    def marker_rms(self) -> float:
        """RMS (m) of all marker distances of all frames (gaps excluded)."""
        e = self.marker_errors[np.isfinite(self.marker_errors)]
        return float(np.sqrt(np.mean(e**2))) if e.size else float("nan")

    def marker_rms_per_frame(self) -> np.ndarray:
        """``(F,)`` RMS over the markers present in each frame (m)."""
        return np.sqrt(np.nanmean(self.marker_errors**2, axis=1))

    def marker_max(self) -> float:
        return float(np.nanmax(self.marker_errors))


def _coordinate_targets(model: Model, tasks: Sequence[CoordinateTask], times: np.ndarray,
                        coordinate_file: Path | None) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Names, weights ``(C,)`` and targets ``(F, C)`` (rad / m) of the coordinate tasks."""
    names, weights, columns = [], [], []
    motion: Table | None = None
    for task in tasks:
        try:
            coordinate = model.coordinate(task.name)
        except KeyError:
            raise InputError(f"IK coordinate task '{task.name}' names no coordinate of the model", file=model.file,
                             element="<IKCoordinateTask>", expected="a coordinate name") from None
        if coordinate.locked:
            warnings.warn(f"IK coordinate task '{task.name}': the coordinate is locked; task ignored", stacklevel=3)
            continue
        if task.value_type == "default_value":
            column = np.full(times.size, coordinate.default_value)
        elif task.value_type == "manual_value":
            column = np.full(times.size, task.value)
        else:
            if coordinate_file is None:
                raise InputError(f"IK coordinate task '{task.name}' takes its value from_file but no coordinate file "
                                 "is given", element="<coordinate_file>", expected="a .mot/.sto of coordinates")
            if motion is None:
                rotational = {c.name: c.range for c in model.coordinates if c.motion_type == "rotational"}
                motion = read_storage(coordinate_file)
                warn_implausible_angles(motion, rotational, file=coordinate_file, stacklevel=4)
                motion = motion.to_radians(rotational)
            column = np.interp(times, motion.time, motion.column(task.name))
        names.append(task.name)
        weights.append(task.weight)
        columns.append(column)
    targets = np.column_stack(columns) if columns else np.zeros((times.size, 0))
    return names, np.array(weights, dtype=float), targets


def tolerances_for_accuracy(accuracy: float | None) -> Tolerances:
    """Stopping rules for OpenSim's ``accuracy`` (its assembler's relative accuracy):
    steps below ``accuracy * 1e-2`` (rad / m) and relative cost changes below ``accuracy**2``.
    """
    accuracy = DEFAULT_ACCURACY if accuracy is None else float(accuracy)
    return Tolerances(xtol=max(accuracy * 1e-2, 1e-14), ftol=max(accuracy**2, 1e-15), gtol=1e-14,
                      max_iterations=500, max_evaluations=2000)


def inverse_kinematics(
    model: Model | str | os.PathLike[str],
    markers: MarkerTable | MarkerTrial | str | os.PathLike[str],
    *,
    weights: Mapping[str, float] | None = None,
    coordinate_tasks: Sequence[CoordinateTask] = (),
    coordinate_file: str | os.PathLike[str] | None = None,
    time_range: tuple[float, float] | None = None,
    accuracy: float | None = None,
    parameters: ModelParameters | None = None,
    parameter_values: np.ndarray | None = None,
    unscaled_marker_bodies: Collection[str] = (),
    initial: np.ndarray | None = None,
    check_marker_units: bool = True,
    kinematics: MarkerKinematics | None = None,
    time_range_source: str | os.PathLike[str] | None = None,
    weights_source: str | os.PathLike[str] | None = None,
) -> IkResult:
    """Inverse kinematics of a marker trial (see module docstring).

    ``model``: a :class:`~nmsm.model.components.Model` or ``.osim`` path. ``markers``: a
    ``.trc`` path, a :class:`~nmsm.io.trc.MarkerTable` or an already selected
    :class:`~nmsm.tools.jmp.marker_data.MarkerTrial`. ``weights``: marker -> weight (the
    markers used; default every marker of both file and model, weight 1).
    ``coordinate_tasks``: IK coordinate tasks (``from_file`` values read from
    ``coordinate_file``). ``time_range`` (s) selects frames. ``accuracy``: OpenSim's IK
    accuracy, mapped by :func:`tolerances_for_accuracy`. ``parameters`` /
    ``parameter_values``: a parameterized model (JMP) and the values to use (default: the
    file's); ``unscaled_marker_bodies``: bodies whose markers do not follow their scale
    factor. ``initial``: free-coordinate start of the first frame (default: the model's
    default pose). ``check_marker_units``: detect mm/m mix-ups (:func:`check_units`).
    ``kinematics``: a :class:`MarkerKinematics` already built for these markers (and
    parameters), to save building it again. ``time_range_source``: the settings file that
    gave ``time_range`` (named when the range reaches beyond the markers). ``weights_source``:
    the IK settings file whose task set gave ``weights``; its tasks naming a marker that the
    marker file or the model lacks are then skipped with a warning, as OpenSim's IK tool
    skips them (without it such a marker is an :class:`InputError`).
    """
    if not isinstance(model, Model):
        model = load_model(model)
    if isinstance(markers, MarkerTrial):
        trial = markers
        if time_range is not None:
            keep = frames_in_range(trial.time, *time_range)
            if not keep.any():
                raise InputError(f"no frame of the marker trial lies in the time range {time_range[0]:g}-"
                                 f"{time_range[1]:g} s (the trial covers {trial.time[0]:g}-{trial.time[-1]:g} s)",
                                 file=trial.source, element="<time_range>",
                                 expected="a time range overlapping the marker data")
            trial = attrs.evolve(trial, time=trial.time[keep], positions=trial.positions[keep])
    else:
        table = markers if isinstance(markers, MarkerTable) else read_trc(markers)
        trial = select_trial(table, model, weights, time_range=time_range,
                             time_range_source=None if time_range_source is None else str(time_range_source),
                             settings_file=None if weights_source is None else str(weights_source),
                             element="<IKMarkerTask>" if weights_source is not None else "<marker_names>",
                             skip_missing=weights_source is not None)
    task_names = [t.name for t in coordinate_tasks]
    if kinematics is not None:
        if kinematics.marker_names != tuple(trial.names) or not set(task_names) <= set(kinematics.free_names):
            raise ValueError("the given kinematics do not match the trial's markers and coordinate tasks")
        kin = kinematics
    else:
        kin = MarkerKinematics(model, trial.names, parameters, unscaled_marker_bodies=unscaled_marker_bodies,
                               extra_free=task_names)
    p = kin.parameters.initial_values if parameter_values is None else np.asarray(parameter_values, dtype=float)
    q0 = kin.initial_free() if initial is None else np.clip(np.asarray(initial, dtype=float), kin.lower, kin.upper)
    factor = 1.0
    if check_marker_units:
        default_positions = kin.marker_positions(q0[None, :], p)[0]
        trial, factor = check_units(trial, default_positions)
    c_names, c_weights, c_targets = _coordinate_targets(
        model, coordinate_tasks, trial.time, None if coordinate_file is None else Path(coordinate_file))
    frame = DenseEvaluator(_frame_function(kin, c_names, c_weights))
    x_exp = trial.filled_positions()  # F x M x 3: column-major 3 x M per frame
    sqrt_w = trial.sqrt_weights()
    tol = tolerances_for_accuracy(accuracy)
    n_frames = trial.n_frames
    q_free = np.zeros((n_frames, kin.n_free))
    iterations = np.zeros(n_frames, dtype=int)
    converged = np.zeros(n_frames, dtype=bool)
    start = time.perf_counter()
    starts = first_frame_starts(q0, kin.lower, kin.upper) if initial is None else [q0]
    q = q0
    for k in range(n_frames):
        args = (p, x_exp[k], sqrt_w[k], c_targets[k])

        def fun(x: np.ndarray, args=args) -> tuple[np.ndarray, DenseJacobian]:
            r, jac = frame(x, *args)
            return r.ravel(), DenseJacobian(jac)

        if k == 0:
            tried = [solve(fun, start, kin.lower, kin.upper, tol) for start in starts]
            result = min(tried, key=lambda r: r.cost)  # the default pose's on a tie
        else:
            result = solve(fun, q, kin.lower, kin.upper, tol)
        q = result.x
        q_free[k] = q
        iterations[k] = result.iterations
        converged[k] = result.converged
    wall = time.perf_counter() - start
    if not converged.all():
        bad = np.flatnonzero(~converged)
        warnings.warn(f"inverse kinematics did not converge in {bad.size} of {n_frames} frames "
                      f"(first at t = {trial.time[bad[0]]:.4g} s)", stacklevel=2)
    q_full = kin.full_coordinates(q_free)
    errors = marker_distance_errors(kin, q_free, p, trial)
    return IkResult(
        time=trial.time, coordinate_names=kin.coordinate_names, q=q_full, marker_names=trial.names,
        marker_errors=errors, weights=trial.weights, free_names=kin.free_names, locked_names=kin.locked_names,
        insensitive_names=kin.insensitive_names,
        rotational=frozenset(c.name for c in model.coordinates if c.motion_type == "rotational"),
        iterations=iterations, converged=converged, wall_time=wall, unit_factor=factor,
    )


def first_frame_starts(q0: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> list[np.ndarray]:
    """Starting points ``(n_free,)`` of the first frame: the default pose ``q0`` and, when some
    bounded coordinate sits on a bound of its range there, the same pose with those coordinates
    at the middle of their range.

    A default on a bound (elbows and knees at 0 in [0, 150 deg]) is where a bound-constrained
    step cannot leave the bound while the markers' pull points outward: the first frame of a
    trial with bent arms then ends with the elbows at 0 and the arms rotated instead (48.8 mm
    RMS against OpenSim's 12.7 mm on the subject-3 tutorial's hips trial); every later frame
    starts there and stays."""
    bounded = np.isfinite(lower) & np.isfinite(upper)
    on_bound = bounded & ((q0 <= lower) | (q0 >= upper))
    if not on_bound.any():
        return [q0]
    moved = q0.copy()
    moved[on_bound] = 0.5 * (lower[on_bound] + upper[on_bound])
    return [q0, moved]


def _frame_function(kin: MarkerKinematics, coordinate_names: Sequence[str], coordinate_weights: np.ndarray) -> cs.Function:
    """One frame: ``(q, p, x_exp 3xM, sqrt_w M, q_ref C) -> (r, dr/dq)``."""
    x_exp = cs.SX.sym("x_exp", 3, kin.n_markers)
    sqrt_w = cs.SX.sym("sqrt_w", kin.n_markers)
    q_ref = cs.SX.sym("q_ref", len(coordinate_names))
    parts = [cs.vec((kin.positions - x_exp) * cs.repmat(cs.transpose(sqrt_w), 3, 1))]
    if coordinate_names:
        index = [kin.coordinate_names.index(n) for n in coordinate_names]
        chosen = cs.vertcat(*[kin.q_full[i] for i in index])
        parts.append(cs.DM(np.sqrt(coordinate_weights)) * (chosen - q_ref))
    r = cs.vertcat(*parts)
    return cs.Function("ik_frame", [kin.q, kin.p, x_exp, sqrt_w, q_ref], [r, cs.jacobian(r, kin.q)])


def marker_distance_errors(kin: MarkerKinematics, q_free: np.ndarray, p: np.ndarray, trial: MarkerTrial) -> np.ndarray:
    """``(F, M)`` distances (m) between model and experimental markers, NaN in gaps."""
    if q_free.shape[0] == 0:
        return np.zeros((0, kin.n_markers))
    model_positions = kin.marker_positions(q_free, p)
    errors = np.linalg.norm(model_positions - trial.positions, axis=2)
    return np.where(trial.present, errors, np.nan)


# ---------------------------------------------------------------------------- files
def motion_table(result: IkResult) -> Table:
    """The solution as OpenSim's IK tool writes it: every coordinate, rotational ones in degrees."""
    table = Table(time=result.time, labels=result.coordinate_names, data=result.q, in_degrees=False,
                  name="Coordinates",
                  comments=("", "Units are S.I. units (second, meters, Newtons, ...)",
                            "If the header above contains a line with 'inDegrees', this indicates whether rotational "
                            "values are in degrees (yes) or radians (no).", ""))
    return table.to_degrees(result.rotational)


def write_motion(path: str | os.PathLike[str], result: IkResult) -> Path:
    """Write ``result`` as an OpenSim ``.mot`` (degrees for rotational coordinates)."""
    return write_storage(path, motion_table(result), name="Coordinates")


def marker_error_table(result: IkResult) -> Table:
    """Per-marker distance errors (m) over time, one column per marker."""
    return Table(time=result.time, labels=result.marker_names, data=result.marker_errors, name="MarkerErrors")


def run_ik_files(model_file: str | os.PathLike[str], marker_file: str | os.PathLike[str] | None = None, *,
                 ik_settings: str | os.PathLike[str] | IkSettings | None = None,
                 output: str | os.PathLike[str] | None = None,
                 time_range: tuple[float, float] | None = None, accuracy: float | None = None) -> IkResult:
    """IK from files, as ``nmsm ik``: settings (if any) give marker weights, coordinate tasks,
    time range, accuracy and, when ``marker_file``/``output`` are not given, those paths.
    Arguments given here override the settings. Writes ``output`` (.mot) when known."""
    settings = read_ik_settings(ik_settings) if isinstance(ik_settings, (str, os.PathLike)) else ik_settings
    if marker_file is None:
        if settings is None or settings.marker_file is None:
            raise InputError("no marker file given", element="MARKERS.trc",
                             expected="a .trc path, or an IK settings file with <marker_file>")
        marker_file = settings.marker_file
    if output is None and settings is not None:
        output = settings.output_motion_file
    if settings is not None and np.isfinite(settings.constraint_weight):
        warnings.warn(f"{settings.file}: <constraint_weight> {settings.constraint_weight:g} ignored: nmsm always "
                      "enforces coordinate couplers exactly (OpenSim's Inf)", stacklevel=2)
    result = inverse_kinematics(
        model_file, marker_file,
        weights=settings.marker_weights if settings else None,
        coordinate_tasks=settings.coordinate_tasks if settings else (),
        coordinate_file=settings.coordinate_file if settings else None,
        time_range=time_range if time_range is not None else (settings.time_range if settings else None),
        accuracy=accuracy if accuracy is not None else (settings.accuracy if settings else None),
        time_range_source=settings.file if time_range is None and settings is not None else None,
        weights_source=settings.file if settings is not None and settings.marker_weights is not None else None,
    )
    if output is not None:
        write_motion(output, result)
    return result

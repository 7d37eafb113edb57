"""The Moco 2D gait tracking problem (``shared/data/moco2d``) as a Tracking Optimization.

:func:`write_problem` writes, into a work folder, the inputs and the settings files of the
torque-driven or muscle-driven tracking of ``referenceCoordinates.sto`` and
``referenceGRF.sto`` with ``2D_gait.osim`` as it is (4 SmoothSphereHalfSpaceForce foot
contacts), set up as close as our formulation allows to the anchors' MocoTrack problem
(``shared/anchors/moco_2d_track.py``, run by the bridge command ``moco_track_2d``):

* cost weights: Moco minimizes ``J = ∫ [Σ_20 states (x - x_ref)² + 10 Σ u² +
  Σ_feet |ΔF_xy|² / (m g)] dt`` (``u`` = excitation, or torque / optimal force). Our
  objective is the mean over terms of ``∫₀¹ (g/e)² ds``; with ``e = 1/sqrt(w)`` per term
  and IPOPT's objective scaled by ``N_terms × T`` (:attr:`MocoProblem.objective_factor`)
  the NLP objective equals Moco's ``J`` term by term, so IPOPT's tolerance means the same;
* mesh: 50 intervals (Moco: Hermite-Simpson, 101 points; ours: Radau with
  ``points_per_interval`` collocation points per interval, 101 nodes with 2);
* periodicity (Moco's endpoint-constraint goal): coordinate values and speeds r<->l,
  pelvis tilt/ty and lumbar values and speeds, pelvis_tx speed, within ±``periodicity_error``;
* dynamics: implicit (``kinetic_consistency`` within ±``dynamics_error``, N·m or N);
  muscle mode: pelvis unactuated (``root_segment_residual_load`` within the same bound),
  torque mode: torque controls on every coordinate (Moco's CoordinateActuators);
* muscles: activations are the controls (Moco: excitations with activation dynamics),
  DeGrooteFregly2016 rigid-tendon forces on the exact path geometry; with
  ``like_moco=True`` as in Moco: excitations are the controls (their squares are the
  effort) and activations states with DeGrooteFregly2016 activation dynamics, periodic
  r<->l, both starting from the midpoint of their bounds (Moco's default guess;
  ``<trial>_combinedActivations.sto`` and ``<trial>_muscleExcitations.sto`` in the
  initial-guess folder);
* ``like_moco=True`` also adds Moco's control periodicity: ``lumbar`` (both modes) and the
  joint torques r<->l (torque mode);
* reference: by default the raw table; the benchmark passes Moco's own 6 Hz low-pass
  filtered table (:func:`states_reference_table`) so both track the same data; bounds:
  range rule around the reference (Moco: the anchors' fixed bounds).

The reference duration is the data's (0.470089 s), the trial is ``gait``. Rotational
coordinates in rad, forces in N.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.io.storage import Table, read_storage, table_from_columns, write_storage

TRIAL = "gait"
COORDINATES = ("pelvis_tilt", "pelvis_tx", "pelvis_ty", "hip_flexion_l", "hip_flexion_r", "knee_angle_l",
               "knee_angle_r", "ankle_angle_l", "ankle_angle_r", "lumbar")
PELVIS = ("pelvis_tilt", "pelvis_tx", "pelvis_ty")
TRANSLATIONS = ("pelvis_tx", "pelvis_ty")
MUSCLE_COORDINATES = ("hip_flexion_l", "hip_flexion_r", "knee_angle_l", "knee_angle_r", "ankle_angle_l",
                      "ankle_angle_r")
#: optimal forces of the anchors' CoordinateActuators (torque mode) and lumbarAct
OPTIMAL_FORCE = {**{c: 50.0 for c in PELVIS}, **{c: 250.0 for c in MUSCLE_COORDINATES}, "lumbar": 1.0}
STATE_WEIGHT = 1.0
EFFORT_WEIGHT = 10.0
GRF_WEIGHT = 1.0
GRF_COLUMNS = ("ground_force_r_vx", "ground_force_r_vy", "ground_force_l_vx", "ground_force_l_vy")
GRAVITY = 9.80665
#: with ``like_moco``: the excitations' and activations' initial guess, the midpoint of their
#: bounds [0.01, 1] (MocoCasADiSolver's default guess)
MOCO_ACTIVATION_GUESS = 0.505
MODES = ("torque", "muscle")


def load_label(coordinate: str) -> str:
    return f"{coordinate}_force" if coordinate in TRANSLATIONS else f"{coordinate}_moment"


def reference_coordinates(data_dir: os.PathLike[str] | str) -> Table:
    """``referenceCoordinates.sto`` with plain coordinate labels (rad, m)."""
    table = read_storage(Path(data_dir) / "referenceCoordinates.sto")
    labels = [label.split("/")[-2] if label.startswith("/") else label for label in table.labels]
    return Table(time=table.time, labels=tuple(labels), data=table.data, in_degrees=False, name=TRIAL)


def states_reference_table(bridge: Any, data_dir: os.PathLike[str] | str, cutoff_frequency: float = 6.0) -> Table:
    """The reference MocoTrack tracks (``TabOpLowPassFilter(6)`` of ``referenceCoordinates.sto``,
    computed by OpenSim through the bridge command ``moco_states_reference``), plain labels."""
    r = bridge.call("moco_states_reference", coordinates_file=str((Path(data_dir) / "referenceCoordinates.sto").resolve()),
                    cutoff_frequency=cutoff_frequency)
    labels = [label.split("/")[-2] if label.startswith("/") else label for label in r["labels"]]
    return Table(time=r["time"], labels=tuple(labels), data=r["data"], in_degrees=False, name=TRIAL)


def _pair(coordinate: str) -> str:
    if coordinate.endswith("_r"):
        return coordinate[:-2] + "_l"
    if coordinate.endswith("_l"):
        return coordinate[:-2] + "_r"
    return coordinate


@attrs.frozen
class MocoProblem:
    """Files of one written problem: ``settings`` (TO settings XML), ``solver`` (solver
    settings XML), ``objective_factor`` (IPOPT ``obj_scaling_factor`` that makes our
    objective Moco's ``J``), ``n_cost_terms``, ``duration`` (s), ``mode``."""

    settings: Path
    solver: Path
    results: Path
    objective_factor: float
    n_cost_terms: int
    duration: float
    mode: str


def _cost(kind: str, error: float, **fields: str) -> str:
    extra = "".join(f"<{k}>{v}</{k}>" for k, v in fields.items())
    return (f"<RCNLCostTerm><is_enabled>true</is_enabled><type>{kind}</type>"
            f"<max_allowable_error>{error:.10g}</max_allowable_error>{extra}</RCNLCostTerm>")


def _constraint(kind: str, bound: float, **fields: str) -> str:
    extra = "".join(f"<{k}>{v}</{k}>" for k, v in fields.items())
    return (f"<RCNLConstraintTerm><is_enabled>true</is_enabled><type>{kind}</type>"
            f"<max_error>{bound:.10g}</max_error><min_error>{-bound:.10g}</min_error>{extra}</RCNLConstraintTerm>")


def write_problem(folder: os.PathLike[str] | str, data_dir: os.PathLike[str] | str, mode: str, *,
                  mesh_intervals: int = 50, points_per_interval: int = 2, tolerance: float = 1e-4,
                  max_iterations: int = 1000, dynamics_error: float = 1e-2, periodicity_error: float = 1e-4,
                  position_range_scale: float = 0.5, velocity_range_scale: float = 4.0,
                  acceleration_range_scale: float = 10.0, torque_range: float = 2000.0,
                  reference: Table | None = None, like_moco: bool = False) -> MocoProblem:
    """Write the ``mode`` ('torque' | 'muscle') problem under ``folder`` (created; nothing is
    written into ``data_dir``). ``reference``: the tracked coordinates (default: the raw
    ``referenceCoordinates.sto``; :func:`states_reference_table` gives Moco's 6 Hz filtered
    one). ``like_moco``: activation dynamics and control periodicity as Moco's problem
    (module docstring). Returns the paths and the objective factor."""
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, not {mode!r}")
    folder = Path(folder).resolve()  # the settings name absolute paths: runnable from anywhere
    data_dir = Path(data_dir).resolve()
    tracked = folder / "tracked"
    for sub in ("IKData", "IDData", "GRFData"):
        (tracked / sub).mkdir(parents=True, exist_ok=True)
    ik = reference if reference is not None else reference_coordinates(data_dir)
    write_storage(tracked / "IKData" / f"{TRIAL}.sto", ik)
    # no measured joint loads: zero ID (sets the torque-control guess to 0, as Moco's guess,
    # and the torque bounds to ±torque_range through the minimum range)
    write_storage(tracked / "IDData" / f"{TRIAL}.sto",
                  table_from_columns(ik.time, {load_label(c): np.zeros(ik.time.size) for c in COORDINATES},
                                     name=TRIAL))
    grf = read_storage(data_dir / "referenceGRF.sto")
    write_storage(tracked / "GRFData" / f"{TRIAL}.sto", grf)
    duration = float(ik.time[-1] - ik.time[0])

    from nmsm.model import load_model

    osim = load_model(data_dir / "2D_gait.osim")
    mass = osim.total_mass()
    muscles = [m.name for m in osim.muscles]

    costs: list[str] = []
    n = 0
    state_error = 1.0 / math.sqrt(STATE_WEIGHT)
    costs.append(_cost("generalized_coordinate_tracking", state_error, coordinate_list=" ".join(COORDINATES)))
    costs.append(_cost("generalized_speed_tracking", state_error, coordinate_list=" ".join(COORDINATES)))
    n += 2 * len(COORDINATES)
    grf_error = math.sqrt(mass * GRAVITY / GRF_WEIGHT)
    costs.append(_cost("external_force_tracking", grf_error, force_list=" ".join(GRF_COLUMNS)))
    n += len(GRF_COLUMNS)
    torque_coordinates = COORDINATES if mode == "torque" else ("lumbar",)
    for c in torque_coordinates:
        costs.append(_cost("controller_minimization", OPTIMAL_FORCE[c] / math.sqrt(EFFORT_WEIGHT), controller=c))
        n += 1
    muscle_block = ""
    if mode == "muscle":
        if like_moco:  # Moco's guess: the bounds' midpoint; its effort: squared excitations (the controls)
            guess = table_from_columns(ik.time, {m: np.full(ik.time.size, MOCO_ACTIVATION_GUESS) for m in muscles},
                                       name=TRIAL)
            for kind in ("combinedActivations", "muscleExcitations"):
                write_storage(tracked / f"{TRIAL}_{kind}.sto", guess)
            for m in muscles:
                costs.append(_cost("controller_minimization", 1.0 / math.sqrt(EFFORT_WEIGHT), controller=m))
        else:
            costs.append(_cost("muscle_activation_minimization", 1.0 / math.sqrt(EFFORT_WEIGHT),
                               muscle_list=" ".join(muscles)))
        n += len(muscles)
        muscle_block = ("<RCNLMuscleController><surrogate_model_coordinate_list>" + " ".join(MUSCLE_COORDINATES)
                        + "</surrogate_model_coordinate_list><muscle_force_model>degroote2016</muscle_force_model>"
                        f"<activation_dynamics>{str(like_moco).lower()}</activation_dynamics>"
                        "<minimum_activation>0.01</minimum_activation></RCNLMuscleController>")
    constraints: list[str] = []
    for c in torque_coordinates:
        constraints.append(_constraint("kinetic_consistency", dynamics_error, load=load_label(c)))
    if mode == "muscle":
        for c in MUSCLE_COORDINATES:
            constraints.append(_constraint("kinetic_consistency", dynamics_error, load=load_label(c)))
        for c in PELVIS:
            constraints.append(_constraint("root_segment_residual_load", dynamics_error, load=load_label(c)))
    for c in COORDINATES:
        if c != "pelvis_tx":
            constraints.append(_constraint("generalized_coordinate_periodicity", periodicity_error, coordinate=c,
                                           pair_coordinate=_pair(c)))
        constraints.append(_constraint("generalized_speed_periodicity", periodicity_error, coordinate=c,
                                       pair_coordinate=_pair(c)))
    if like_moco:
        constraints.append(_constraint("controller_periodicity", periodicity_error, controller="lumbar"))
        if mode == "torque":
            for c in MUSCLE_COORDINATES:
                constraints.append(_constraint("controller_periodicity", periodicity_error, controller=c,
                                               pair_controller=_pair(c)))
        else:
            for m in muscles:
                constraints.append(_constraint("muscle_activation_periodicity", periodicity_error, muscle=m,
                                               pair_muscle=_pair(m)))
    results = folder / f"results_{mode}"
    solver = folder / "solver.xml"
    solver.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.0"><OptimalControlSolverSettings><GpopsSettings>
 <setup_mesh_method>none</setup_mesh_method>
 <setup_mesh_phase_intervals>{mesh_intervals}</setup_mesh_phase_intervals>
 <setup_mesh_phase_colpoints_per_Interval>{points_per_interval}</setup_mesh_phase_colpoints_per_Interval>
 <setup_nlp_linear_solver>mumps</setup_nlp_linear_solver>
 <setup_nlp_tolerance>{tolerance:g}</setup_nlp_tolerance>
 <setup_nlp_max_iterations>{max_iterations}</setup_nlp_max_iterations>
 <setup_display_level>0</setup_display_level>
</GpopsSettings></OptimalControlSolverSettings></NMSMPipelineDocument>
""", encoding="utf-8")
    cost_text = "\n  ".join(costs)
    constraint_text = "\n  ".join(constraints)
    settings = folder / f"to_{mode}.xml"
    settings.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.0"><TrackingOptimizationTool>
 <trial_name>{TRIAL}</trial_name>
 <results_directory>{results}</results_directory>
 <input_model_file>{data_dir / "2D_gait.osim"}</input_model_file>
 <initial_guess_directory>{tracked}</initial_guess_directory>
 <tracked_quantities_directory>{tracked}</tracked_quantities_directory>
 <optimal_control_solver_settings_file>{solver}</optimal_control_solver_settings_file>
 <states_coordinate_list>{" ".join(COORDINATES)}</states_coordinate_list>
 <joint_position_range_scale_factor>{position_range_scale:g}</joint_position_range_scale_factor>
 <joint_velocity_range_scale_factor>{velocity_range_scale:g}</joint_velocity_range_scale_factor>
 <joint_acceleration_range_scale_factor>{acceleration_range_scale:g}</joint_acceleration_range_scale_factor>
 <RCNLTorqueController><coordinate_list>{" ".join(torque_coordinates)}</coordinate_list>
  <torque_controls_range_scale_factor>1</torque_controls_range_scale_factor>
  <torque_controls_minimum_range>{torque_range:g}</torque_controls_minimum_range></RCNLTorqueController>
 {muscle_block}
 <RCNLCostTermSet>
  {cost_text}
 </RCNLCostTermSet>
 <RCNLConstraintTermSet>
  {constraint_text}
 </RCNLConstraintTermSet>
</TrackingOptimizationTool></NMSMPipelineDocument>
""", encoding="utf-8")
    return MocoProblem(settings, solver, results, n * duration, n, duration, mode)


ROTATIONS = tuple(c for c in COORDINATES if c not in TRANSLATIONS)


@attrs.frozen
class TrackingError:
    """RMS over the solution's time points of solution - reference: ``coordinates_deg``
    (rotational coordinates pooled, deg), ``translations_mm`` (pelvis tx, ty pooled, mm),
    ``grf_n`` (``GRF_COLUMNS`` pooled, N); references interpolated by cubic splines of the
    reference coordinates and of ``referenceGRF.sto``."""

    coordinates_deg: float
    translations_mm: float
    grf_n: float


def tracking_error(data_dir: os.PathLike[str] | str, time: np.ndarray, coordinates: dict[str, np.ndarray],
                   grf: dict[str, np.ndarray], reference: Table | None = None) -> TrackingError:
    """Errors of a solution given as ``time`` (n,) s, coordinate name -> (n,) rad/m and
    ground-reaction column -> (n,) N, against ``reference`` (default: the raw coordinates)."""
    from scipy.interpolate import CubicSpline

    ref = reference if reference is not None else reference_coordinates(data_dir)
    ref_grf = read_storage(Path(data_dir) / "referenceGRF.sto")
    t = np.clip(np.asarray(time, dtype=float), ref.time[0], ref.time[-1])

    def rms(table: Table, names: tuple[str, ...], values: dict[str, np.ndarray], scale: float) -> float:
        errors = [CubicSpline(table.time, table.data[:, table.labels.index(c)])(t) - np.asarray(values[c]).ravel()
                  for c in names]
        return float(np.sqrt(np.mean(np.square(errors))) * scale)

    return TrackingError(rms(ref, ROTATIONS, coordinates, 180.0 / math.pi), rms(ref, TRANSLATIONS, coordinates, 1e3),
                         rms(ref_grf, GRF_COLUMNS, grf, 1.0))


def read_solution(results: os.PathLike[str] | str) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray]]:
    """(time, coordinates, ground reactions) of a results folder of :func:`write_problem`'s runs."""
    results = Path(results)
    states = read_storage(results / f"{TRIAL}_states.sto")
    grf = read_storage(results / "GRFData" / f"{TRIAL}.sto")
    coordinates = {c: states.data[:, states.labels.index(c)] for c in COORDINATES}
    forces = {c: np.interp(states.time, grf.time, grf.data[:, grf.labels.index(c)]) for c in GRF_COLUMNS}
    return states.time, coordinates, forces

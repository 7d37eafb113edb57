"""A synthetic Tracking Optimization at full-body scale, for profiling (``bench_treatment_scale``).

Built from ``treatment/torque_kick_tutorial`` (the 41-coordinate, 86-muscle KickingModel,
its kicking trial's IK and ID) into a scratch folder:

* ``n_states`` state coordinates (up to 31: pelvis, hips, knees, ankles, subtalar, mtp,
  lumbar, shoulders, elbows), all tracked, with inverse dynamics loads tracked and
  kinetic consistency on the actuated ones;
* ``muscles_per_leg`` muscles of each leg (the model's ``right_leg``/``left_leg`` groups,
  first ones in the group's order) driven by ``synergies`` synergies per leg, synergy
  vectors optimized, over 6 surrogate coordinates per leg; torque controls on the other
  state coordinates;
* **synthetic** geometry and neural data: each muscle's lengths and moment arms are those of
  one of the 9 right-leg muscles of ``synergy_kick_tutorial/surrogateData`` (cycled, the
  left leg's on the left coordinates), synergy vectors are seeded random numbers and the
  synergy commands a smooth guess; the activations tracked are ``C W`` of that guess.

The numbers of such a problem (variables, constraints, Hessian non-zeros, time per
evaluation) are those of a full-body case of the same dimensions; its optimum is not a
biomechanical result.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from nmsm.io.storage import Table, read_storage, write_storage

DATA = Path(os.environ.get("NMSM_SHARED_DATA") or Path(__file__).resolve().parents[2] / "shared" / "data") / "treatment"
TORQUE = DATA / "torque_kick_tutorial"
SYNERGY = DATA / "synergy_kick_tutorial"
TRIAL = "drive_kick1"

#: the 31 state coordinates of a full-body gait problem, in the order they are taken
STATE_COORDINATES = (
    "pelvis_tilt pelvis_list pelvis_rotation pelvis_tx pelvis_ty pelvis_tz "
    "hip_flexion_r hip_adduction_r hip_rotation_r knee_angle_r ankle_angle_r subtalar_angle_r "
    "hip_flexion_l hip_adduction_l hip_rotation_l knee_angle_l ankle_angle_l subtalar_angle_l "
    "mtp_angle_r mtp_angle_l lumbar_extension lumbar_bending lumbar_rotation "
    "arm_flex_r arm_add_r arm_rot_r arm_flex_l arm_add_l arm_rot_l elbow_flex_r elbow_flex_l").split()
LEG_COORDINATES = ("hip_flexion", "hip_adduction", "hip_rotation", "knee_angle", "ankle_angle", "subtalar_angle")
ROOT = ("pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx", "pelvis_ty", "pelvis_tz")


def _group_members(model_file: Path, group: str) -> list[str]:
    text = model_file.read_text()
    start = text.index(f'<ObjectGroup name="{group}">')
    members = text[start:].split("<members>", 1)[1].split("</members>", 1)[0]
    return members.split()


def _set_group_members(model_file: Path, muscles: dict[str, list[str]]) -> None:
    """The copied model's ``right_leg``/``left_leg`` groups reduced to the chosen muscles."""
    text = model_file.read_text()
    for side, group in (("r", "right_leg"), ("l", "left_leg")):
        start = text.index(f'<ObjectGroup name="{group}">')
        a = text.index("<members>", start) + len("<members>")
        b = text.index("</members>", a)
        text = text[:a] + " " + " ".join(muscles[side]) + text[b:]
    model_file.write_text(text)


def _surrogate_data(folder: Path, muscles: dict[str, list[str]]) -> None:
    source = SYNERGY / "surrogateData"
    (folder / "IKData").mkdir(parents=True, exist_ok=True)
    shutil.copy2(source / "IKData" / f"{TRIAL}.sto", folder / "IKData" / f"{TRIAL}.sto")
    ma = source / "MAData" / TRIAL
    out = folder / "MAData" / TRIAL
    out.mkdir(parents=True, exist_ok=True)
    length = read_storage(next(ma.glob("*_Length.sto")))
    src = list(length.labels)
    arms = {c: read_storage(next(ma.glob(f"*_MomentArm_{c}_r.sto"))) for c in LEG_COORDINATES}
    names = [m for side in ("r", "l") for m in muscles[side]]
    L = np.column_stack([length.column(src[k % len(src)]) for k, _ in enumerate(muscles["r"])] * 2)
    write_storage(out / f"{TRIAL}_Length.sto", Table(time=length.time, labels=names, data=L, name="Length"))
    for c in LEG_COORDINATES:
        for side in ("r", "l"):
            cols = []
            for other in ("r", "l"):
                for k, _ in enumerate(muscles[other]):
                    cols.append(arms[c].column(src[k % len(src)]) if other == side else np.zeros(length.n_rows))
            write_storage(out / f"{TRIAL}_MomentArm_{c}_{side}.sto",
                          Table(time=length.time, labels=names, data=np.column_stack(cols), name="MomentArm"))


def _osimx(path: Path, synergies: int) -> None:
    sets = "".join(f"<RCNLSynergy><muscle_group_name>{g}</muscle_group_name><num_synergies>{synergies}"
                   f"</num_synergies></RCNLSynergy>" for g in ("right_leg", "left_leg"))
    path.write_text('<?xml version="1.0" encoding="utf-8"?>\n<NMSMPipelineDocument Version="1.5.0"><OsimxModel '
                    'name="KickingModel"><associated_osim_model>KickingModel.osim</associated_osim_model>'
                    f"<RCNLSynergySet>{sets}</RCNLSynergySet></OsimxModel></NMSMPipelineDocument>\n")


def _neural_guess(folder: Path, time: np.ndarray, muscles: dict[str, list[str]], synergies: int) -> None:
    rng = np.random.default_rng(24)
    names = [f"{g}_{k}" for g in ("right_leg", "left_leg") for k in range(1, synergies + 1)]
    s = (time - time[0]) / (time[-1] - time[0])
    C = np.column_stack([0.15 + 0.1 * np.sin(2 * np.pi * (s + j / len(names))) ** 2 for j in range(len(names))])
    n_r, n_l = len(muscles["r"]), len(muscles["l"])
    W = np.zeros((2 * synergies, n_r + n_l))
    W[:synergies, :n_r] = rng.uniform(0.0, 1.0, (synergies, n_r))
    W[synergies:, n_r:] = rng.uniform(0.0, 1.0, (synergies, n_l))
    W /= W.sum(axis=1, keepdims=True)
    W *= 6.0  # activations C W of order 0.1
    all_muscles = muscles["r"] + muscles["l"]
    write_storage(folder / f"{TRIAL}_synergyCommands.sto", Table(time=time, labels=names, data=C, name="commands"))
    write_storage(folder / "synergyWeights.sto",
                  Table(time=np.arange(1.0, 2 * synergies + 1), labels=all_muscles, data=W, name="weights"))
    write_storage(folder / f"{TRIAL}_combinedActivations.sto",
                  Table(time=time, labels=all_muscles, data=C @ W, name="activations"))


def _terms(states: list[str], muscles: list[str], actuated: list[str]) -> tuple[str, str]:
    coords = " ".join(states)
    loads = " ".join(f"{c}_force" if c.endswith(("_tx", "_ty", "_tz")) else f"{c}_moment" for c in actuated)
    costs = (f'<RCNLCostTerm name="Coordinate tracking"><is_enabled>true</is_enabled><type>generalized_coordinate_tracking'
             f"</type><coordinate_list>{coords}</coordinate_list><max_allowable_error>0.0873</max_allowable_error>"
             "</RCNLCostTerm>"
             f'<RCNLCostTerm name="Load tracking"><is_enabled>true</is_enabled><type>inverse_dynamics_load_tracking'
             f"</type><load_list>{loads}</load_list><max_allowable_error>50</max_allowable_error></RCNLCostTerm>")
    if muscles:
        costs += (f'<RCNLCostTerm name="Activation tracking"><is_enabled>true</is_enabled><type>muscle_activation_tracking'
                  f"</type><muscle_list>{' '.join(muscles)}</muscle_list><max_allowable_error>0.1</max_allowable_error>"
                  "</RCNLCostTerm>")
    constraints = (f'<RCNLConstraintTerm name="Kinetic consistency"><type>kinetic_consistency</type><load_list>{loads}'
                   "</load_list><is_enabled>true</is_enabled><max_error>0.1</max_error><min_error>-0.1</min_error>"
                   "</RCNLConstraintTerm>")
    return costs, constraints


def write_case(folder: Path, *, intervals: int = 25, points: int = 4, n_states: int = 31, muscles_per_leg: int = 43,
               synergies: int = 5, max_iterations: int = 300) -> Path:
    """Write the settings and data of the synthetic case into ``folder``; returns the TO
    settings file. ``muscles_per_leg`` 0: torque-driven."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    model = folder / "KickingModel.osim"
    shutil.copy2(TORQUE / "KickingModel.osim", model)
    shutil.copytree(TORQUE / "preprocessed", folder / "preprocessed", dirs_exist_ok=True)
    states = STATE_COORDINATES[:n_states]
    muscles = {s: _group_members(model, f"{'right' if s == 'r' else 'left'}_leg")[:muscles_per_leg] for s in "rl"}
    if muscles_per_leg:
        _set_group_members(model, muscles)
    surrogate = [f"{c}_{s}" for s in "rl" for c in LEG_COORDINATES]
    guess = folder / "guess"
    shutil.copytree(folder / "preprocessed", guess, dirs_exist_ok=True)
    ik = read_storage(folder / "preprocessed" / "IKData" / f"{TRIAL}.sto")
    controllers = ""
    if muscles_per_leg:
        _surrogate_data(folder / "surrogateData", muscles)
        _osimx(folder / "KickingModel.osimx", synergies)
        _neural_guess(guess, ik.time, muscles, synergies)
        controllers += ("<RCNLSynergyController><optimize_synergy_vectors>true</optimize_synergy_vectors>"
                        "<synergy_vector_normalization_method>sum</synergy_vector_normalization_method>"
                        "<synergy_vector_normalization_value>6</synergy_vector_normalization_value>"
                        "<maximum_allowable_synergy_activation>2</maximum_allowable_synergy_activation>"
                        f"<surrogate_model_coordinate_list>{' '.join(surrogate)}</surrogate_model_coordinate_list>"
                        "<surrogate_model_data_directory>surrogateData</surrogate_model_data_directory>"
                        "</RCNLSynergyController>")
        torque = [c for c in states if c not in surrogate and c not in ROOT]
    else:
        torque = [c for c in states if c not in ROOT]
    if torque:
        controllers += f"<RCNLTorqueController><coordinate_list>{' '.join(torque)}</coordinate_list></RCNLTorqueController>"
    actuated = [c for c in states if c not in ROOT and (c in torque or c in surrogate)]
    costs, constraints = _terms(list(states), muscles["r"] + muscles["l"] if muscles_per_leg else [], actuated)
    osimx = "<input_osimx_file>KickingModel.osimx</input_osimx_file>" if muscles_per_leg else "<input_osimx_file/>"
    gpops = (TORQUE / "GpopsSettings.xml").read_text()
    gpops = _set(gpops, "setup_mesh_phase_intervals", str(intervals))
    gpops = _set(gpops, "setup_mesh_phase_colpoints_per_Interval", str(points))
    gpops = _set(gpops, "setup_nlp_max_iterations", str(max_iterations))
    (folder / "GpopsSettings.xml").write_text(gpops)
    settings = folder / "ScaleTOSettings.xml"
    settings.write_text(
        '<?xml version="1.0" encoding="UTF-8" ?>\n<NMSMPipelineDocument Version="1.5.0"><TrackingOptimizationTool '
        'name="default"><results_directory>ScaleTOResults</results_directory><initial_guess_directory>guess'
        "</initial_guess_directory><tracked_quantities_directory>preprocessed</tracked_quantities_directory>"
        f"<input_model_file>KickingModel.osim</input_model_file>{osimx}"
        "<optimal_control_solver_settings_file>GpopsSettings.xml</optimal_control_solver_settings_file>"
        f"<trial_name>{TRIAL}</trial_name><states_coordinate_list>{' '.join(states)}</states_coordinate_list>"
        "<joint_position_range_scale_factor>1.5</joint_position_range_scale_factor>"
        "<joint_velocity_range_scale_factor>1.25</joint_velocity_range_scale_factor>"
        "<joint_acceleration_range_scale_factor>1</joint_acceleration_range_scale_factor>"
        f"{controllers}<RCNLCostTermSet>{costs}</RCNLCostTermSet><RCNLConstraintTermSet>{constraints}"
        "</RCNLConstraintTermSet></TrackingOptimizationTool></NMSMPipelineDocument>\n")
    return settings


def _set(xml: str, tag: str, value: str) -> str:
    start = xml.index(f"<{tag}>") + len(tag) + 2
    end = xml.index(f"</{tag}>", start)
    return xml[:start] + value + xml[end:]

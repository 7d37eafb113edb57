"""Bad input and solver failure: clear messages, no result that looks converged."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError, SolverError
from nmsm.tools.treatment.run import run_settings

TEMPLATE = """<NMSMPipelineDocument Version="1.5.0"><{tool}>
 <results_directory>{results}</results_directory>
 <initial_guess_directory>{data}/preprocessed</initial_guess_directory>
 <tracked_quantities_directory>{data}/preprocessed</tracked_quantities_directory>
 <input_model_file>{data}/KickingModel.osim</input_model_file><input_osimx_file/>
 <optimal_control_solver_settings_file>{data}/GpopsSettings.xml</optimal_control_solver_settings_file>
 <trial_name>drive_kick1</trial_name><states_coordinate_list>{states}</states_coordinate_list>
 <RCNLTorqueController><coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list></RCNLTorqueController>
 <RCNLCostTermSet>{costs}</RCNLCostTermSet>
 <RCNLConstraintTermSet><RCNLConstraintTerm><is_enabled>true</is_enabled><type>kinetic_consistency</type>
  <load_list>hip_flexion_r_moment knee_angle_r_moment ankle_angle_r_moment</load_list>
  <max_error>0.1</max_error><min_error>-0.1</min_error></RCNLConstraintTerm></RCNLConstraintTermSet>
</{tool}></NMSMPipelineDocument>"""
COORDINATES = ("<RCNLCostTerm><is_enabled>true</is_enabled><type>generalized_coordinate_tracking</type>"
               "<coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>"
               "<max_allowable_error>0.0873</max_allowable_error></RCNLCostTerm>")
LOADS = ("<RCNLCostTerm><is_enabled>true</is_enabled><type>inverse_dynamics_load_tracking</type>"
         "<load_list>hip_flexion_r_moment</load_list><max_allowable_error>50</max_allowable_error></RCNLCostTerm>")


def _settings(shared: Path, tmp: Path, *, tool: str = "TrackingOptimizationTool",
              states: str = "hip_flexion_r knee_angle_r ankle_angle_r", costs: str = COORDINATES + LOADS) -> Path:
    data = shared / "treatment" / "torque_kick_tutorial"
    path = tmp / "settings.xml"
    path.write_text(TEMPLATE.format(tool=tool, results=tmp / "results", data=data, states=states, costs=costs))
    return path


def _quiet_run(path: Path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_settings(path, **options)


def test_term_not_allowed_in_verification(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path, tool="VerificationOptimizationTool")
    with pytest.raises(InputError, match=r"'inverse_dynamics_load_tracking' is not allowed in Verification") as info:
        _quiet_run(path)
    assert "settings.xml" in str(info.value)


def test_coupled_coordinate_cannot_be_a_state(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path, states="hip_flexion_r knee_angle_r_beta")
    with pytest.raises(InputError, match="coordinate coupler"):
        _quiet_run(path)


def test_unknown_coordinate_in_a_term_names_file_and_line(shared_data: Path, tmp_path: Path) -> None:
    costs = COORDINATES.replace("ankle_angle_r</coordinate_list>", "ankle_r</coordinate_list>")
    path = _settings(shared_data, tmp_path, costs=costs)
    message = r"settings.xml:\d+: <coordinate_list>: term 'generalized_coordinate_tracking': coordinate 'ankle_r'"
    with pytest.raises(InputError, match=message):
        _quiet_run(path)


def test_uncontrolled_untracked_state_is_reported(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path, states="hip_flexion_r knee_angle_r ankle_angle_r lumbar_extension")
    with pytest.warns(UserWarning, match="'lumbar_extension' is neither actuated by a controller nor tracked"):
        run_settings(path, evaluate_only=True)


def test_solver_failure_keeps_the_last_iterate_apart(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path)
    with pytest.raises(SolverError, match="did not converge") as info:
        _quiet_run(path, max_iterations=1, print_level=0)
    saved = Path(info.value.last_iterate_path)
    assert (saved / "diagnosis.txt").read_text().count("Maximum_Iterations_Exceeded") >= 1
    assert (saved / "drive_kick1_states.sto").is_file()
    assert not (tmp_path / "results" / "drive_kick1_states.sto").exists()


def test_unwritable_results_folder(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path)
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(InputError, match="cannot create the results folder"):
        _quiet_run(path, results_directory=blocker / "results", print_level=0)


def test_verification_coordinate_both_controlled_and_tracked_is_reported(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path, tool="VerificationOptimizationTool", costs=COORDINATES)
    with pytest.warns(UserWarning, match="VO: state coordinate 'knee_angle_r' is both controlled and tracked"):
        run_settings(path, evaluate_only=True)


def test_initial_guess_outside_the_bounds_is_reported(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.io.storage import read_storage, table_from_columns, write_storage

    states = ("hip_flexion_r", "knee_angle_r", "ankle_angle_r")
    ik = read_storage(shared_data / "treatment" / "torque_kick_tutorial" / "preprocessed" / "IKData" / "drive_kick1.sto")
    ik = ik.to_radians(states)
    columns = {c: ik.column(c) + (5.0 if c == "hip_flexion_r" else 0.0) for c in states}
    columns |= {f"{c}_u": np.gradient(ik.column(c), ik.time) for c in states}
    guess = tmp_path / "guess"
    guess.mkdir()
    write_storage(guess / "drive_kick1_states.sto", table_from_columns(ik.time, columns))
    path = _settings(shared_data, tmp_path)
    with pytest.warns(UserWarning, match=r"initial guess violates variable bounds.*\n.*state 'hip_flexion_r': "
                                         r"initial guess spans \[.*\] outside the bounds \[.*\]") as record:
        run = run_settings(path, initial_guess_directory=guess, evaluate_only=True)
    assert not any("knee_angle_r'" in str(w.message) for w in record if "violates" in str(w.message))
    # IPOPT starts from the projection onto the bounds
    lo, hi = run.prepared.built.problem.bounds_scaled()
    assert np.all(run.solution.x_scaled >= lo) and np.all(run.solution.x_scaled <= hi)



def test_final_time_guess_outside_the_range_is_reported(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path, tool="DesignOptimizationTool")
    text = path.read_text()
    path.write_text(text.replace("<RCNLCostTermSet>", "<final_time_range>3 4</final_time_range><RCNLCostTermSet>"))
    with pytest.warns(UserWarning, match=r"initial guess violates variable bounds.*\n.*final time <final_time_range>: "
                                         r"initial guess 0.31 s \(duration of drive_kick1.sto\) outside the bounds "
                                         r"\[3, 4\]"):
        run = run_settings(path, evaluate_only=True)
    assert run.prepared.data.final_time_guess == 3.0  # IPOPT starts from the projection
    path.write_text(text.replace("<RCNLCostTermSet>", "<final_time_range>0.2 0.4</final_time_range><RCNLCostTermSet>"))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        run = run_settings(path, evaluate_only=True)
    assert not any("final time" in str(w.message) for w in record)
    assert run.prepared.data.final_time_guess == pytest.approx(0.31)


INFEASIBLE = ("<RCNLConstraintTerm><is_enabled>true</is_enabled><type>generalized_coordinate_value</type>"
              "<coordinate_list>knee_angle_r</coordinate_list><max_error>6</max_error><min_error>5</min_error>"
              "</RCNLConstraintTerm></RCNLConstraintTermSet>")


def test_infeasible_problem_is_diagnosed_and_never_looks_converged(shared_data: Path, tmp_path: Path) -> None:
    # knee angle in [5, 6] rad while its bounds (range rule on the data) stay far below;
    # a coarse mesh (4 x 3 points) keeps IPOPT's infeasibility detection short
    data = shared_data / "treatment" / "torque_kick_tutorial"
    solver = tmp_path / "solver.xml"
    solver.write_text((data / "GpopsSettings.xml").read_text()
                      .replace("<setup_mesh_phase_intervals>25<", "<setup_mesh_phase_intervals>4<")
                      .replace("<setup_mesh_phase_colpoints_per_Interval>4<", "<setup_mesh_phase_colpoints_per_Interval>3<"))
    path = _settings(shared_data, tmp_path)
    path.write_text(path.read_text().replace("</RCNLConstraintTermSet>", INFEASIBLE)
                    .replace(str(data / "GpopsSettings.xml"), str(solver)))
    with pytest.raises(SolverError, match="did not converge") as info:
        _quiet_run(path, max_iterations=200, print_level=0)
    saved = Path(info.value.last_iterate_path)
    diagnosis = (saved / "diagnosis.txt").read_text()
    assert "Infeasible" in diagnosis and "locally infeasible" in diagnosis
    assert re.search(r"\[VIOLATED\] generalized_coordinate_value:knee_angle_r .*settings.xml:\d+\)", diagnosis)
    assert (saved / "drive_kick1_convergence.txt").is_file()
    assert not (tmp_path / "results" / "drive_kick1_states.sto").exists()
    assert not (tmp_path / "results" / "IKData").exists()


def test_constraint_bounds_in_the_wrong_order(shared_data: Path, tmp_path: Path) -> None:
    path = _settings(shared_data, tmp_path)
    path.write_text(path.read_text().replace("<max_error>0.1</max_error><min_error>-0.1</min_error>",
                                             "<max_error>-0.1</max_error><min_error>0.1</min_error>"))
    with pytest.raises(InputError, match=r"settings.xml.*min_error 0.1 > max_error -0.1"):
        _quiet_run(path, evaluate_only=True)


def test_results_folder_cannot_be_an_input_folder(shared_data: Path, tmp_path: Path) -> None:
    toy = shared_data / "treatment" / "toy_arm"
    to = tmp_path / "to"
    _quiet_run(toy / "tracking_optimization" / "TorqueDrivenTOSettings.xml", results_directory=to, print_level=0)
    before = (to / "arm1_states.sto").read_bytes()
    with pytest.raises(InputError, match="is the tracked quantities folder .*: the results would mix"):
        _quiet_run(toy / "verification_optimization" / "TorqueDrivenVOSettings.xml", results_directory=to,
                   initial_guess_directory=to, tracked_quantities_directory=to, print_level=0)
    with pytest.raises(InputError, match="is inside the tracked quantities folder"):
        _quiet_run(toy / "verification_optimization" / "TorqueDrivenVOSettings.xml", results_directory=to / "vo",
                   initial_guess_directory=to, tracked_quantities_directory=to, print_level=0)
    assert (to / "arm1_states.sto").read_bytes() == before
    assert not (to / "vo").exists()


def test_failed_rerun_leaves_no_earlier_result_looking_like_its_own(shared_data: Path, tmp_path: Path) -> None:
    settings = shared_data / "treatment" / "toy_arm" / "tracking_optimization" / "TorqueDrivenTOSettings.xml"
    to = tmp_path / "to"
    _quiet_run(settings, results_directory=to, print_level=0)
    written = sorted(p.relative_to(to) for p in to.rglob("*") if p.is_file() and not p.name.startswith("."))
    assert Path("arm1_states.sto") in written and Path("arm1_ipopt.log") in written
    (to / "notes.txt").write_text("the user's")
    with pytest.raises(SolverError, match=r"did not converge.*earlier run wrote for trial 'arm1' were moved to "
                                          r".*superseded") as info:
        _quiet_run(settings, results_directory=to, print_level=0, max_iterations=1)
    assert Path(info.value.last_iterate_path) == to / "last_iterate"
    # nothing of the earlier run at the top level, no half-written IPOPT log, the user's file
    # kept; the run's record lists the last iterate's files (a later run retires them)
    assert sorted(p.name for p in to.iterdir()) == [".nmsm-outputs-arm1.txt", "last_iterate", "notes.txt",
                                                    "superseded"]
    assert (to / "notes.txt").read_text() == "the user's"
    assert sorted(p.relative_to(to / "superseded") for p in (to / "superseded").rglob("*")
                  if p.is_file() and not p.name.startswith(".")) == written
    assert "Solve_Succeeded" in (to / "superseded" / "arm1_convergence.txt").read_text()
    assert "Maximum_Iterations_Exceeded" in (to / "last_iterate" / "arm1_convergence.txt").read_text()

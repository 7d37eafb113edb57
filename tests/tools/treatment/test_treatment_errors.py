"""Bad input and solver failure: clear messages, no result that looks converged."""

from __future__ import annotations

import warnings
from pathlib import Path

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

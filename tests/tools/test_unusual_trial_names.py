"""Trial, body and problem names that are not CasADi names (``gait.1``, ``gait 1``, ``Gang_ü1``,
``R.ASIS``) run like plain ones: CasADi refuses such function names with a traceback
(``Function name is not valid``), so nmsm builds its function names with
:func:`nmsm.core.function_names.function_name`."""

from __future__ import annotations

import shutil

import casadi as cs
import numpy as np
import pytest

from nmsm.core.function_names import function_name
from nmsm.core.problem import OptimizationProblem
from nmsm.io.storage import read_storage
from nmsm.tools.mtp.run import run_settings


def _mtp_settings(folder, tutorial):
    """A short MTP run of the tutorial's data (one task, two cost terms, no MTLI)."""
    path = folder / "MTPSettings.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.0"><MuscleTendonPersonalizationTool>
 <results_directory>results</results_directory>
 <input_model_file>{tutorial / 'UF_Subject_3_reduced_muscles.osim'}</input_model_file>
 <input_osimx_file/>
 <data_directory>preprocessed</data_directory>
 <normalized_fiber_length_muscle_groups/>
 <coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>
 <activation_muscle_groups>HamslatActivationGroupR</activation_muscle_groups>
 <missing_emg_channel_muscle_groups>HipFlexorsMissingEMGChannelGroup</missing_emg_channel_muscle_groups>
 <collected_emg_channel_muscle_groups>GlutMaxLat RecFem BicFemLong BicFemShort VastMed GasMed Sol TibAnt</collected_emg_channel_muscle_groups>
 <max_iterations>50</max_iterations>
 <MuscleTendonLengthInitialization><is_enabled>false</is_enabled></MuscleTendonLengthInitialization>
 <MTPSynergyExtrapolation><is_enabled>false</is_enabled></MTPSynergyExtrapolation>
 <MTPTaskList><MTPTask><is_enabled>true</is_enabled>
  <muscle_specific_electromechanical_delays>true</muscle_specific_electromechanical_delays><RCNLCostTermSet>
  <RCNLCostTerm><is_enabled>true</is_enabled><type>inverse_dynamics_joint_moment</type>
   <max_allowable_error>2.5</max_allowable_error></RCNLCostTerm>
  <RCNLCostTerm><is_enabled>true</is_enabled><type>emg_scale_factor</type>
   <max_allowable_error>0.2</max_allowable_error><error_center>0.3</error_center></RCNLCostTerm>
 </RCNLCostTermSet></MTPTask></MTPTaskList>
</MuscleTendonPersonalizationTool></NMSMPipelineDocument>""")
    return path


@pytest.mark.parametrize(
    "parts, expected",
    [
        (("mtp_activation", "gait.1"), "mtp_activation_gait_1"),
        (("mtp_force", "gait 1"), "mtp_force_gait_1"),
        (("marker", "R.ASIS"), "marker_R_ASIS"),
        (("TO", "Gang_ü1"), "TO_Gang_1"),
        (("pose", "r__foot_"), "pose_r_foot"),
        (("1st trial",), "f_1st_trial"),
        (("",), "f"),
        (("jac",), "jac_f"),
    ],
)
def test_function_name_is_a_valid_casadi_name(parts, expected):
    name = function_name(*parts)
    assert name == expected
    x = cs.SX.sym("x")
    cs.Function(name, [x], [x])  # CasADi's own check


def test_ipopt_solves_a_problem_named_after_a_dotted_trial():
    prob = OptimizationProblem("TO_gait.1 ü")
    x = prob.variable("x", [0.0])
    prob.add_cost("fit", x - 2.0)
    sol = prob.solve("ipopt", print_level=0)
    assert abs(sol["x"].item() - 2.0) < 1e-6


@pytest.mark.parametrize("trial", ["gait.1", "gait 1", "Gang_ü1"])
def test_mtp_trial_names_with_dots_spaces_and_accents(tmp_path, shared_data, trial):
    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    results = {}
    for name in ("gait_1", trial):
        folder = tmp_path / name
        shutil.copytree(tutorial / "preprocessed", folder / "preprocessed")
        for path in sorted((folder / "preprocessed").rglob("gait_1*"), key=lambda p: -len(p.parts)):
            path.rename(path.with_name(path.name.replace("gait_1", name)))
        run_settings(_mtp_settings(folder, tutorial), accept_unconverged=True)
        results[name] = read_storage(folder / "results" / "muscleActivations" / f"{name}_muscleActivations.sto")
    np.testing.assert_array_equal(results[trial].data, results["gait_1"].data)

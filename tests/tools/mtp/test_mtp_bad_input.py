"""Bad MTP input gives clear errors (file, element or column, expected), never NaN results."""

from __future__ import annotations

import shutil
import types
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.mtp.run import prepare, run_settings

TERMS = """
<RCNLCostTerm><is_enabled>true</is_enabled><type>inverse_dynamics_joint_moment</type>
  <max_allowable_error>2.5</max_allowable_error></RCNLCostTerm>
<RCNLCostTerm><is_enabled>true</is_enabled><type>emg_scale_factor</type>
  <max_allowable_error>0.2</max_allowable_error><error_center>0.3</error_center></RCNLCostTerm>"""


def write_settings(folder: Path, tutorial: Path, *, channels: str = "GlutMaxLat RecFem BicFemLong BicFemShort VastMed GasMed Sol TibAnt",
                   osimx: str = "") -> Path:
    """A short MTP run of the tutorial's data (50 iterations, one task: it stops before IPOPT's
    tolerance, so its callers accept unconverged results)."""
    text = f"""<NMSMPipelineDocument Version="1.5.0"><MuscleTendonPersonalizationTool>
 <results_directory>results</results_directory>
 <input_model_file>{tutorial / 'UF_Subject_3_reduced_muscles.osim'}</input_model_file>
 <input_osimx_file>{osimx}</input_osimx_file>
 <data_directory>preprocessed</data_directory>
 <coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>
 <activation_muscle_groups>HamslatActivationGroupR</activation_muscle_groups>
 <normalized_fiber_length_muscle_groups/>
 <missing_emg_channel_muscle_groups>HipFlexorsMissingEMGChannelGroup</missing_emg_channel_muscle_groups>
 <collected_emg_channel_muscle_groups>{channels}</collected_emg_channel_muscle_groups>
 <max_iterations>50</max_iterations>
 <MuscleTendonLengthInitialization><is_enabled>false</is_enabled></MuscleTendonLengthInitialization>
 <MTPSynergyExtrapolation><is_enabled>false</is_enabled></MTPSynergyExtrapolation>
 <MTPTaskList><MTPTask><is_enabled>true</is_enabled>
  <muscle_specific_electromechanical_delays>true</muscle_specific_electromechanical_delays>
  <RCNLCostTermSet>{TERMS}</RCNLCostTermSet></MTPTask></MTPTaskList>
</MuscleTendonPersonalizationTool></NMSMPipelineDocument>"""
    path = folder / "MTPSettings.xml"
    path.write_text(text)
    return path


def test_runs_clean(case):
    folder, tutorial = case
    outcome = run_settings(write_settings(folder, tutorial), accept_unconverged=True)
    assert (folder / "results" / "UF_Subject_3_reduced_muscles_mtp.osimx").is_file()
    assert np.isfinite(outcome.tasks[0].cost)


def test_emg_channel_not_a_model_group(case):
    folder, tutorial = case
    settings = write_settings(folder, tutorial, channels="GlutMaxLat RecFem Bogus")
    with pytest.raises(InputError) as info:
        prepare(settings)
    message = str(info.value)
    assert "Bogus" in message and "collected_emg_channel_muscle_groups" in message and "GlutMaxLat" in message
    assert message.startswith(str(settings)), message  # the file holding the element, the model named too
    assert ".osim" in message


def test_emg_column_missing(case):
    folder, tutorial = case
    path = folder / "preprocessed" / "EMGData" / "gait_1.sto"
    table = read_storage(path)
    keep = [label for label in table.labels if label != "RecFem"]
    write_storage(path, table.select(keep))
    with pytest.raises(InputError) as info:
        prepare(write_settings(folder, tutorial))
    assert "RecFem" in str(info.value) and "gait_1.sto" in str(info.value)


def test_trials_with_different_frame_counts(case):
    folder, tutorial = case
    data = folder / "preprocessed"
    for sub in ("IDData", "EMGData", "IKData"):
        table = read_storage(data / sub / "gait_1.sto")
        cut = slice(0, table.n_rows - 2)
        shortened = table_from_columns(table.time[cut], {l: table.column(l)[cut] for l in table.labels})
        write_storage(data / sub / "gait_2.sto", shortened)
    ma = data / "MAData"
    shutil.copytree(ma / "gait_1", ma / "gait_2")
    for f in (ma / "gait_2").iterdir():
        table = read_storage(f)
        cut = slice(0, table.n_rows - 2)
        write_storage(f.with_name(f.name.replace("gait_1", "gait_2")),
                      table_from_columns(table.time[cut], {l: table.column(l)[cut] for l in table.labels}))
        f.unlink()
    with pytest.raises(InputError, match="different frame counts"):
        prepare(write_settings(folder, tutorial))


def test_missing_moment_arm_file(case):
    folder, tutorial = case
    (folder / "preprocessed" / "MAData" / "gait_1" / "gait_1_MomentArm_knee_angle_r.sto").unlink()
    with pytest.raises(InputError) as info:
        prepare(write_settings(folder, tutorial))
    assert "knee_angle_r" in str(info.value) and "moment-arm" in str(info.value)


def test_zero_tendon_slack_length_is_rejected(case):
    folder, tutorial = case
    osimx = folder / "bad.osimx"
    osimx.write_text("""<NMSMPipelineDocument Version="1.5.3"><OsimxModel name="m">
 <associated_osim_model>m.osim</associated_osim_model><RCNLMuscleSet>
 <RCNLMuscle name="soleus_r"><tendon_slack_length>0</tendon_slack_length></RCNLMuscle>
 </RCNLMuscleSet></OsimxModel></NMSMPipelineDocument>""")
    with pytest.raises(InputError) as info:
        prepare(write_settings(folder, tutorial, osimx=str(osimx)))
    assert "tendon_slack_length" in str(info.value) and "soleus_r" in str(info.value)


def test_tendon_slack_length_above_muscle_tendon_length(case):
    """l_ts >= L_MT (no fiber left): refused up front, naming muscle, trial and lengths."""
    folder, tutorial = case
    osimx = folder / "long.osimx"
    osimx.write_text("""<NMSMPipelineDocument Version="1.5.3"><OsimxModel name="m">
 <associated_osim_model>m.osim</associated_osim_model><RCNLMuscleSet>
 <RCNLMuscle name="soleus_r"><tendon_slack_length>0.9</tendon_slack_length></RCNLMuscle>
 </RCNLMuscleSet></OsimxModel></NMSMPipelineDocument>""")
    with pytest.raises(InputError) as info:
        prepare(write_settings(folder, tutorial, osimx=str(osimx)))
    message = str(info.value)
    assert "soleus_r" in message and "gait_1" in message and "0.9" in message and "long.osimx" in message


def test_tiny_tendon_slack_length_gives_finite_results(case):
    """l_ts near zero (the original blew up): guarded maths; results finite or a clear error."""
    folder, tutorial = case
    osimx = folder / "tiny.osimx"
    osimx.write_text("""<NMSMPipelineDocument Version="1.5.3"><OsimxModel name="m">
 <associated_osim_model>m.osim</associated_osim_model><RCNLMuscleSet>
 <RCNLMuscle name="tibant_r"><tendon_slack_length>1e-6</tendon_slack_length></RCNLMuscle>
 </RCNLMuscleSet></OsimxModel></NMSMPipelineDocument>""")
    settings = write_settings(folder, tutorial, osimx=str(osimx))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome = run_settings(settings, max_iterations=30, accept_unconverged=True)
    assert np.isfinite(outcome.tasks[0].cost)
    for path in (folder / "results").rglob("*.sto"):
        assert np.all(np.isfinite(read_storage(path).data)), path.name


def test_non_finite_modeled_values_raise_an_nmsm_error():
    """A non-finite modeled value is a SolverError (an nmsm error the CLI reports), not FloatingPointError."""
    import casadi as cs

    from nmsm.errors import NmsmError, SolverError
    from nmsm.tools.mtp.evaluation import _FIELDS, _numeric

    values = {name: cs.MX(cs.DM(np.ones((3, 2)))) for name in _FIELDS}
    values["tendon_force"] = cs.MX(cs.DM(np.array([[1.0, np.nan], [1.0, 1.0], [1.0, 1.0]])))
    with pytest.raises(SolverError, match="modeled tendon_force is not finite") as info:
        _numeric([types.SimpleNamespace(**values)])
    assert isinstance(info.value, NmsmError)


def test_non_finite_values_are_not_written(tmp_path):
    from nmsm.errors import SolverError
    from nmsm.tools.mtp.outputs import _write

    path = tmp_path / "Analysis" / "gait_1_tendonForces.sto"
    with pytest.raises(SolverError, match="refusing to write non-finite values to gait_1_tendonForces.sto"):
        _write(path, np.array([0.0, 0.01]), ["soleus_r"], np.array([[1.0], [np.inf]]))
    assert not path.exists()

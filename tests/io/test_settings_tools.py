"""Tool settings classes: every shared settings file, values, defaults and bad input."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.settings import (
    SETTINGS_CLASSES,
    DesignOptimizationSettings,
    GroundContactPersonalizationSettings,
    JointModelPersonalizationSettings,
    MuscleTendonPersonalizationSettings,
    NeuralControlPersonalizationSettings,
    OptimalControlSolverSettings,
    TrackingOptimizationSettings,
    VerificationOptimizationSettings,
    read_settings_document,
    read_tool_settings,
    settings_from_document,
)

_SETTINGS_ROOTS = {"NMSMPipelineDocument", "GpopsDocument"}


def nmsm_settings_files(root: Path) -> list[Path]:
    """Every NMSM settings XML (OpenSim tool settings such as IKSettings are not NMSM's)."""
    out = []
    for path in sorted(root.rglob("*.xml")):
        if "MAData" in path.parts:
            continue
        try:
            first = etree.parse(str(path)).getroot()
        except etree.XMLSyntaxError:
            continue
        tools = [c.tag for c in first if isinstance(c.tag, str)]
        if first.tag in _SETTINGS_ROOTS or any(t.endswith("PersonalizationTool") for t in tools):
            out.append(path)
    return out


def _quiet_settings(path: Path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_tool_settings(path, **options)


@pytest.mark.shared_data
def test_every_shared_settings_file(shared_data: Path) -> None:
    files = nmsm_settings_files(shared_data)
    assert len(files) == 60
    outcomes: dict[str, str] = {}
    for path in files:
        relative = path.relative_to(shared_data).as_posix()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            doc = read_settings_document(path)
            doc.term_specs(doc.tool_element)
            try:
                settings = settings_from_document(doc)
            except InputError as exc:
                outcomes[relative] = f"error: {exc.detail}"
                continue
        assert type(settings) is SETTINGS_CLASSES[doc.tool], relative
        outcomes[relative] = "ok"
    errors = {k: v for k, v in outcomes.items() if v != "ok"}
    references = {k for k in outcomes if k.endswith("XMLReference.xml")}
    assert len(references) == 10
    for name in references:  # templates with empty required elements
        assert errors.pop(name).startswith("error: required element <input_model_file> is empty in <"), name
    for name in ("JointModelPersonalizationSettings.xml", "JointModelPersonalizationSettingsBJF.xml", "SimpleXML.xml"):
        message = errors.pop(f"core/nmsm_core_tests/parse/{name}")  # 2021 parse fixtures, no model shipped
        assert message.startswith("error: 'Patient3.osim' not found")
    assert not errors, errors


@pytest.mark.shared_data
def test_jmp_tutorial_values(shared_data: Path) -> None:
    step = shared_data / "jmp/uf_subject3_tutorial"
    s = _quiet_settings(step / "CompletedSettingsFiles/JMPSettingsSequential.xml")
    assert isinstance(s, JointModelPersonalizationSettings)
    assert [t.name for t in s.tasks] == ["Scale Hips", "Right Knee", "Right Ankle"] and [t.index for t in s.tasks] == [
        1,
        2,
        3,
    ]
    assert s.tasks[0].marker_file_name == (step / "MarkerFiles/BothHips_markers.trc").resolve()
    assert (
        s.tasks[0].time_range == (0.0, 10.41)
        and s.tasks[0].bodies[0].name == "pelvis"
        and s.tasks[0].bodies[0].scale_body
    )
    knee = s.tasks[1].joints[0]
    assert knee.name == "knee_r" and knee.parent_frame_transformation.orientation == (True, True, False)
    assert (
        knee.parent_frame_transformation.translation_bounds == 0.05
        and knee.child_frame_transformation.orientation_bounds == 2.0
    )
    assert s.input_model_file == (step / "CompletedSettingsFiles/UF_Subject_3_Scaled.osim").resolve()
    assert (
        s.allowable_error == 0.01
        and s.accuracy == 1e-6
        and s.max_function_evaluations == 200
        and s.diff_min_change == 0.001
    )
    assert s.output_model_path == (step / "CompletedSettingsFiles/UF_Subject_3_Scaled_Sequential.osim").resolve()
    assert s.tasks[2].first_bound("orientation_bounds") == 1.0


@pytest.mark.shared_data
def test_mtp_tutorial_values(shared_data: Path) -> None:
    step = shared_data / "mtp/uf_subject3_tutorial"
    s = _quiet_settings(step / "CompletedSettingsFiles/MTPSettingsV3.xml")
    assert isinstance(s, MuscleTendonPersonalizationSettings)
    assert s.coordinate_list == ("hip_flexion_r", "knee_angle_r", "ankle_angle_r") and s.input_osimx_file is None
    assert s.data_directory == (step / "preprocessed").resolve() and s.trial_prefixes == ()
    assert s.results_directory == (step / "CompletedSettingsFiles/MTPResultsV3").resolve()
    mtli = s.muscle_tendon_length_initialization
    assert mtli.is_enabled and mtli.passive_data_input_directory == (step / "passive_moment_data").resolve()
    assert mtli.min_normalized_muscle_fiber_length == 0.6 and mtli.maximum_muscle_stress == 610000.0
    assert [t.type for t in mtli.cost_terms][:2] == ["passive_joint_moment", "optimal_muscle_fiber_length"]
    assert not s.synergy_extrapolation.is_enabled and s.synergy_extrapolation.number_of_synergies == 3
    (task,) = s.tasks
    assert task.optimize_tendon_slack_lengths and task.max_normalized_muscle_fiber_length == 1.05  # parser default
    assert len(task.cost_terms) == 12 and task.cost_terms[1].fields["error_center"] == "0.014999999999999999"
    assert s.max_iterations == 1000 and s.max_function_evaluations == 100_000_000


@pytest.mark.shared_data
def test_ncp_gcp_and_treatment_values(shared_data: Path) -> None:
    ncp = _quiet_settings(shared_data / "ncp/uf_subject3_tutorial/CompletedSettingsFiles/NCPSettingsV2.xml")
    assert isinstance(ncp, NeuralControlPersonalizationSettings)
    assert (
        ncp.input_osimx_file.name == "UF_Subject_3_reduced_muscles_mtp.osimx"
        and ncp.mtp_results_directory.name == "mtpResults"
    )
    assert [(g.muscle_group_name, g.num_synergies) for g in ncp.synergy_groups] == [("RightLeg", 4)]
    assert ncp.enforce_bilateral_symmetry is False and ncp.optimality_tolerance == 1e-6

    gcp_dir = shared_data / "gcp/uf_subject3_tutorial"
    gcp = _quiet_settings(gcp_dir / "CompletedSettingsFiles/GCPSettingsV4.xml")
    assert isinstance(gcp, GroundContactPersonalizationSettings)
    assert (
        gcp.input_motion_file == (gcp_dir / "preprocessed/IKData/gait_1.sto").resolve()
    )  # relative to input_directory
    assert (gcp.grid_width, gcp.grid_height) == (8, 15) and gcp.initial_damping_factor == 1.0
    (foot,) = gcp.contact_surfaces
    assert foot.name == "Right foot" and foot.hindfoot_body == "calcn_r" and foot.end_time == 1.6000000000000001
    assert [t.index for t in gcp.tasks] == [1, 2, 3] and gcp.tasks[0].design_flags["restingSpringLength"]
    assert not gcp.tasks[1].design_flags["restingSpringLength"] and gcp.tasks[0].neighborStandardDeviation == 0.2

    to_dir = shared_data / "treatment/synergy_kick_tutorial"
    to = _quiet_settings(to_dir / "CompletedSettingsFiles/SynergyTOSettingsV5.xml")
    assert isinstance(to, TrackingOptimizationSettings) and to.tool_code == "TO"
    synergy = to.synergy_controller
    assert synergy.load_surrogate_model is True  # written next to the controller, found as the original does
    assert synergy.optimize_synergy_vectors and synergy.synergy_vector_normalization_method == "magnitude"
    assert synergy.surrogate_model_data_directory == (to_dir / "surrogateData").resolve()
    assert to.torque_controller is None and to.joint_velocity_range_scale_factor == 1.25
    assert [c.type for c in to.cost_terms][:2] == ["generalized_coordinate_tracking", "generalized_speed_tracking"]
    assert to.constraint_terms[0].fields["name"] == "Kinetic consistency"

    do = _quiet_settings(shared_data / "treatment/torque_kick_tutorial/CompletedSettingsFiles/TorqueDOSettingsV4.xml")
    assert isinstance(do, DesignOptimizationSettings) and do.final_time_range == (0.26, 0.36)
    assert do.optimal_control_solver_settings_file.name == "GpopsSettings.xml"  # wrong case in the file, matched
    user = next(c for c in do.cost_terms if c.type == "user_defined")
    assert user.fields["target_speed"] == "14.35"

    solver = _quiet_settings(to_dir / "gpopsSettings.xml")
    assert isinstance(solver, OptimalControlSolverSettings)
    gpops = solver.gpops
    assert gpops.setup_method == "RPM-Integration"  # "RPM-integration" in the file
    assert gpops.collocation_points == 50 and gpops.setup_mesh_tolerance == 1e-2 and gpops.integral_bound == 1.0


@pytest.mark.shared_data
def test_wrong_case_path_warns(shared_data: Path) -> None:
    path = shared_data / "treatment/torque_kick_tutorial/CompletedSettingsFiles/TorqueTOSettingsV1.xml"
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        read_tool_settings(path)
    messages = [str(w.message) for w in record]
    assert any(
        "'gpopsSettings.xml' does not exist with this letter case" in m and "spelled 'GpopsSettings.xml' on disk" in m
        for m in messages
    )
    assert sum("not next to the settings file" in m for m in messages) == 1  # once per file


# ----- small files written here ---------------------------------------------------------
@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name in ("model.osim", "markers.trc", "solver.xml"):
        (tmp_path / name).write_text("x")
    (tmp_path / "data" / "IDData").mkdir(parents=True)
    return tmp_path


JMP = """<NMSMPipelineDocument Version="1.5.0"><JointModelPersonalizationTool>
 <input_model_file>model.osim</input_model_file><output_model_file>out\\model_jmp.osim</output_model_file>
 <allowable_error>0.01</allowable_error>
 <JMPTaskList>
  <JMPTask name="b"><is_enabled>true</is_enabled><index>2</index><marker_file_name>markers.trc</marker_file_name>
   <JMPBodySet><JMPBody name="pelvis"><scale_body>true</scale_body></JMPBody></JMPBodySet></JMPTask>
  <JMPTask name="off"><is_enabled>false</is_enabled><index>3</index><marker_file_name>markers.trc</marker_file_name></JMPTask>
  <JMPTask name="a"><is_enabled>true</is_enabled><index>1</index><marker_file_name>markers.trc</marker_file_name>
   <JMPJointSet><JMPJoint name="knee_r">
    <parent_frame_transformation><translation>true false false</translation><orientation>false false false</orientation></parent_frame_transformation>
    <child_frame_transformation><translation>false false false</translation><orientation>false false true</orientation></child_frame_transformation>
   </JMPJoint></JMPJointSet></JMPTask>
 </JMPTaskList>
</JointModelPersonalizationTool></NMSMPipelineDocument>
"""


def _write(folder: Path, text: str) -> Path:
    path = folder / "settings.xml"
    path.write_text(text)
    return path


def test_jmp_tasks_sorted_enabled_and_defaults(folder: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s = read_tool_settings(_write(folder, JMP))
    assert [t.name for t in s.tasks] == ["a", "b"]
    assert s.results_directory == folder.resolve() and s.output_model_path == folder.resolve() / "model_jmp.osim"
    assert (s.diff_min_change, s.optimality_tolerance, s.max_function_evaluations, s.accuracy) == (
        1e-4,
        1e-6,
        3000,
        None,
    )
    assert s.tasks[0].joints[0].child_frame_transformation.orientation == (False, False, True)
    assert s.tasks[1].bodies[0].move_markers == (False, False, False)
    assert s.tasks[0].source.line == 8 and s.settings_file == folder / "settings.xml"


def test_tasks_need_an_index_when_several(folder: Path) -> None:
    with pytest.raises(InputError) as info:
        read_tool_settings(_write(folder, JMP.replace("<index>2</index>", "")))
    assert info.value.element == "<index>" and info.value.line == 5
    with pytest.raises(InputError, match="index 1 used twice"):
        read_tool_settings(_write(folder, JMP.replace("<index>2</index>", "<index>1</index>")))


def test_missing_required_element_names_element_and_file(folder: Path) -> None:
    path = _write(folder, JMP.replace("<allowable_error>0.01</allowable_error>", ""))
    with pytest.raises(InputError) as info:
        read_tool_settings(path)
    assert info.value.file == str(path) and info.value.element == "<allowable_error>" and info.value.line == 1
    with pytest.raises(InputError, match="required element <JMPTaskList> is missing"):
        read_tool_settings(
            _write(
                folder, JMP[: JMP.index(" <JMPTaskList>")] + "</JointModelPersonalizationTool></NMSMPipelineDocument>"
            )
        )


def test_missing_file_names_the_element_and_line(folder: Path) -> None:
    path = _write(
        folder,
        JMP.replace(
            '<marker_file_name>markers.trc</marker_file_name></JMPTask>\n  <JMPTask name="a">',
            '<marker_file_name>markers.trc</marker_file_name></JMPTask>\n  <JMPTask name="a">',
            1,
        ).replace("<index>1</index><marker_file_name>markers.trc", "<index>1</index><marker_file_name>gone.trc"),
    )
    with pytest.raises(InputError) as info:
        read_tool_settings(path)
    assert info.value.element == "<marker_file_name>" and info.value.line == 8 and "gone.trc" in info.value.detail
    s = read_tool_settings(path, check_paths=False)  # templates and previews
    assert s.tasks[0].marker_file_name == folder.resolve() / "gone.trc"


def test_bad_values_name_the_element(folder: Path) -> None:
    with pytest.raises(InputError) as info:
        read_tool_settings(
            _write(
                folder,
                JMP.replace("<translation>true false false</translation>", "<translation>true false</translation>"),
            )
        )
    assert info.value.element == "<translation>" and "3 space-separated" in info.value.expected
    with pytest.raises(InputError, match="must be > 0"):
        read_tool_settings(_write(folder, JMP.replace("0.01</allowable_error>", "0</allowable_error>")))


def test_unknown_and_misplaced_elements_warn(folder: Path) -> None:
    text = JMP.replace(
        "<allowable_error>0.01</allowable_error>",
        "<allowable_eror>0.01</allowable_eror><allowable_error>0.01</allowable_error>",
    )
    with pytest.warns(UserWarning, match="unknown element <allowable_eror>.*did you mean <allowable_error>"):
        read_tool_settings(_write(folder, text))
    nested = JMP.replace('<JMPBody name="pelvis">', '<JMPBody name="pelvis"><accuracy>1e-5</accuracy>')
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        s = read_tool_settings(_write(folder, nested))
    messages = [str(w.message) for w in record]
    assert s.accuracy is None
    assert any("<accuracy> is inside <JMPBody>" in m and "depth-first lookup would use it" in m for m in messages)
    assert any("unknown element <accuracy> in <JMPBody>" in m for m in messages)


def test_wrong_tool_class(folder: Path) -> None:
    doc = read_settings_document(_write(folder, JMP))
    with pytest.raises(InputError, match="this is a <JointModelPersonalizationTool> settings file"):
        MuscleTendonPersonalizationSettings.from_document(doc)


TREATMENT = """<NMSMPipelineDocument Version="1.5.0"><{tool}>
 <results_directory/><initial_guess_directory>data</initial_guess_directory><tracked_quantities_directory/>
 <input_model_file>model.osim</input_model_file>{osimx}
 <optimal_control_solver_settings_file>solver.xml</optimal_control_solver_settings_file>
 <trial_name>gait_1</trial_name><states_coordinate_list>knee_angle_r</states_coordinate_list>
 {controllers}
 <RCNLCostTermSet/><RCNLConstraintTermSet/>{extra}
</{tool}></NMSMPipelineDocument>
"""
TORQUE = "<RCNLTorqueController><coordinate_list>knee_angle_r</coordinate_list></RCNLTorqueController>"
SYNERGY = (
    "<RCNLSynergyController><surrogate_model_coordinate_list>knee_angle_r</surrogate_model_coordinate_list>"
    "<surrogate_model_data_directory>data</surrogate_model_data_directory>"
    "<optimize_synergy_vectors>true</optimize_synergy_vectors></RCNLSynergyController>"
)


def _treatment(folder: Path, tool: str, controllers: str = TORQUE, osimx: str = "", extra: str = "") -> Path:
    return _write(folder, TREATMENT.format(tool=tool, controllers=controllers, osimx=osimx, extra=extra))


def test_treatment_defaults_and_controllers(folder: Path) -> None:
    s = read_tool_settings(_treatment(folder, "TrackingOptimizationTool"))
    assert (
        s.joint_position_range_scale_factor,
        s.joint_velocity_range_scale_factor,
        s.joint_acceleration_range_scale_factor,
    ) == (2.0, 1.5, 1.0)
    assert (
        s.tracked_quantities_directory == folder.resolve() and s.initial_guess_directory == (folder / "data").resolve()
    )
    assert s.torque_controller.torque_controls_range_scale_factor == 1.0 and s.synergy_controller is None
    assert s.cost_terms == () and s.constraint_terms == ()
    with pytest.raises(InputError, match="no controller"):
        read_tool_settings(_treatment(folder, "TrackingOptimizationTool", controllers=""))
    with pytest.raises(InputError, match="needs <input_osimx_file>"):
        read_tool_settings(_treatment(folder, "TrackingOptimizationTool", controllers=SYNERGY))
    (folder / "m.osimx").write_text("x")
    with_osimx = "<input_osimx_file>m.osimx</input_osimx_file>"
    s = read_tool_settings(_treatment(folder, "TrackingOptimizationTool", controllers=SYNERGY, osimx=with_osimx))
    assert s.synergy_controller.epsilon == 1e-4 and s.synergy_controller.synergy_vector_normalization_method == "sum"
    with pytest.raises(InputError, match="keeps synergy vectors fixed"):
        read_tool_settings(_treatment(folder, "VerificationOptimizationTool", controllers=SYNERGY, osimx=with_osimx))
    assert isinstance(
        read_tool_settings(_treatment(folder, "VerificationOptimizationTool")), VerificationOptimizationSettings
    )


def test_design_optimization_extras(folder: Path) -> None:
    extra = """
 <final_time_range>0.9 1.3</final_time_range><model_functions>setBeltSpeed</model_functions>
 <RCNLParameterTermSet><RCNLParameterTerm><type>belt_speed</type><is_left_foot>false</is_left_foot>
   <initial_values>1.4</initial_values><lower_bounds>1.0</lower_bounds><upper_bounds>1.8</upper_bounds>
 </RCNLParameterTerm></RCNLParameterTermSet>"""
    s = read_tool_settings(_treatment(folder, "DesignOptimizationTool", extra=extra))
    assert s.final_time_range == (0.9, 1.3) and s.model_functions == ("setBeltSpeed",)
    (p,) = s.parameter_terms
    assert p.type == "belt_speed" and p.initial_values == (1.4,) and p.fields["is_left_foot"] == "false"
    with pytest.raises(InputError, match="outside"):
        read_tool_settings(
            _treatment(
                folder, "DesignOptimizationTool", extra=extra.replace("<initial_values>1.4", "<initial_values>2.4")
            )
        )
    with pytest.raises(InputError, match="start < end"):
        read_tool_settings(_treatment(folder, "DesignOptimizationTool", extra=extra.replace("0.9 1.3", "1.3 0.9")))


MUSCLE = """<NMSMPipelineDocument Version="1.5.0"><{tool}>
 <results_directory>out</results_directory><input_model_file>model.osim</input_model_file><input_osimx_file/>
 <data_directory>data</data_directory><coordinate_list>knee_angle_r</coordinate_list>
 <activation_muscle_groups/><normalized_fiber_length_muscle_groups/>
 <MuscleTendonLengthInitialization><is_enabled>false</is_enabled>
   <passive_data_input_directory>not_here</passive_data_input_directory></MuscleTendonLengthInitialization>
 {body}
</{tool}></NMSMPipelineDocument>
"""


def test_mtp_and_ncp_parser_defaults(folder: Path) -> None:
    mtp_body = (
        "<collected_emg_channel_muscle_groups>Vas</collected_emg_channel_muscle_groups>"
        "<MTPSynergyExtrapolation><is_enabled>false</is_enabled></MTPSynergyExtrapolation>"
        "<MTPTaskList><MTPTask><is_enabled>true</is_enabled>"
        "<muscle_specific_electromechanical_delays>true</muscle_specific_electromechanical_delays>"
        "<RCNLCostTermSet/></MTPTask></MTPTaskList>"
    )
    mtp = read_tool_settings(_write(folder, MUSCLE.format(tool="MuscleTendonPersonalizationTool", body=mtp_body)))
    assert (mtp.max_iterations, mtp.max_function_evaluations, mtp.step_tolerance, mtp.v_max_factor) == (
        10000,
        100_000_000,
        1e-6,
        10.0,
    )
    assert (
        mtp.muscle_tendon_length_initialization.passive_data_input_directory == (folder / "not_here").resolve()
    )  # disabled: not checked
    assert (
        mtp.tasks[0].min_normalized_muscle_fiber_length == 0.75 and mtp.results_directory == (folder / "out").resolve()
    )
    synx_on = mtp_body.replace(
        "<MTPSynergyExtrapolation><is_enabled>false</is_enabled>",
        "<MTPSynergyExtrapolation><is_enabled>true</is_enabled><number_of_synergies>3</number_of_synergies><synergy_extrapolation_categorization>Trial</synergy_extrapolation_categorization><residual_categorization>task</residual_categorization>",
    )
    with pytest.raises(InputError, match="missing_emg_channel_muscle_groups"):
        read_tool_settings(_write(folder, MUSCLE.format(tool="MuscleTendonPersonalizationTool", body=synx_on)))
    with_missing = synx_on + "<missing_emg_channel_muscle_groups>Ham</missing_emg_channel_muscle_groups>"
    mtp = read_tool_settings(_write(folder, MUSCLE.format(tool="MuscleTendonPersonalizationTool", body=with_missing)))
    assert mtp.synergy_extrapolation.synergy_extrapolation_categorization == "trial"
    with pytest.raises(InputError, match="one of PCA, NMF"):
        read_tool_settings(
            _write(
                folder,
                MUSCLE.format(
                    tool="MuscleTendonPersonalizationTool",
                    body=with_missing.replace(
                        "<number_of_synergies>",
                        "<matrix_factorization_method>SVD</matrix_factorization_method><number_of_synergies>",
                    ),
                ),
            )
        )

    ncp_body = (
        "<RCNLCostTermSet/><RCNLSynergySet><RCNLSynergy><muscle_group_name>R</muscle_group_name>"
        "<num_synergies>5</num_synergies></RCNLSynergy></RCNLSynergySet>"
    )
    ncp = read_tool_settings(_write(folder, MUSCLE.format(tool="NeuralControlPersonalizationTool", body=ncp_body)))
    assert (ncp.step_tolerance, ncp.optimality_tolerance, ncp.max_iterations, ncp.max_function_evaluations) == (
        1e-16,
        1e-3,
        1000,
        1_000_000,
    )
    with pytest.raises(InputError, match="exactly two synergy groups"):
        read_tool_settings(
            _write(
                folder,
                MUSCLE.format(
                    tool="NeuralControlPersonalizationTool",
                    body=ncp_body + "<enforce_bilateral_symmetry>true</enforce_bilateral_symmetry>",
                ),
            )
        )
    enabled = MUSCLE.replace(
        "<is_enabled>false</is_enabled>",
        "<is_enabled>true</is_enabled><optimize_maximum_muscle_stress>true</optimize_maximum_muscle_stress>",
    )
    with pytest.raises(InputError, match="'not_here' not found"):
        read_tool_settings(_write(folder, enabled.format(tool="NeuralControlPersonalizationTool", body=ncp_body)))
    with pytest.raises(InputError, match="required element <input_osimx_file> is missing"):
        read_tool_settings(
            _write(
                folder,
                MUSCLE.replace("<input_osimx_file/>", "").format(
                    tool="NeuralControlPersonalizationTool", body=ncp_body
                ),
            )
        )


def test_gcp_old_toe_coordinate_in_current_schema_is_an_error(folder: Path) -> None:
    (folder / "data" / "ik.sto").write_text("x")
    text = """<NMSMPipelineDocument Version="1.5.0"><GroundContactPersonalizationTool>
 <results_directory/><input_directory>data</input_directory><input_model_file>model.osim</input_model_file>
 <input_motion_file>ik.sto</input_motion_file><input_grf_file>ik.sto</input_grf_file>
 <GCPContactSurfaceSet><GCPContactSurface><is_enabled>true</is_enabled><is_left_foot>false</is_left_foot>
  <start_time>0</start_time><end_time>1</end_time><belt_speed>0</belt_speed>
  <electrical_center_columns>px py pz</electrical_center_columns><hindfoot_body>calcn_r</hindfoot_body>
  <toe_marker>T</toe_marker><medial_marker>M</medial_marker><lateral_marker>L</lateral_marker>
  <heel_marker>H</heel_marker><midfoot_superior_marker>S</midfoot_superior_marker>
 </GCPContactSurface></GCPContactSurfaceSet>
 <GCPTaskList><GCPTask><is_enabled>true</is_enabled><RCNLCostTermSet/></GCPTask></GCPTaskList>
</GroundContactPersonalizationTool></NMSMPipelineDocument>"""
    s = read_tool_settings(_write(folder, text))
    assert s.input_motion_file == (folder / "data" / "ik.sto").resolve() and s.latching_velocity == 0.05
    assert s.tasks[0].neighborStandardDeviation == 0.05 and not any(s.tasks[0].design_flags.values())
    with pytest.warns(UserWarning, match="not checked: the model could not be read"):  # 1.0 element, accepted
        old = read_tool_settings(
            _write(
                folder, text.replace("<hindfoot_body>", "<toes_coordinate>mtp_angle_r</toes_coordinate><hindfoot_body>")
            )
        )
    assert old.contact_surfaces[0].hindfoot_body == "calcn_r"
    with pytest.raises(InputError, match="must name 3 columns"):
        read_tool_settings(_write(folder, text.replace("px py pz", "px py")))


def test_moco_solver_is_not_implemented(folder: Path) -> None:
    text = '<NMSMPipelineDocument Version="1.5.0"><OptimalControlSolverSettings><MocoSettings/><GpopsSettings/></OptimalControlSolverSettings></NMSMPipelineDocument>'
    with pytest.raises(InputError, match="not implemented"):
        read_tool_settings(_write(folder, text))
    ok = read_tool_settings(_write(folder, text.replace("<MocoSettings/>", "")))
    assert ok.gpops.setup_nlp_max_iterations == 20000 and ok.gpops.setup_mesh_method == "hp-PattersonRao"

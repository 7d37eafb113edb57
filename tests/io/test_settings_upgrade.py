"""Upgrade of every older settings schema in the shared data to the current one."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.settings import read_settings_document, read_tool_settings, settings_from_document
from nmsm.io.settings.document import parse_settings_xml
from nmsm.io.settings.upgrade import detect_schema, upgrade_settings_file, upgrade_tree

#: every old-schema settings file of the shared data -> its schema
OLD_FILES = {
    "core/nmsm_core_tests/parse/JointModelPersonalizationSettings.xml": "opensim-2023",
    "core/nmsm_core_tests/parse/JointModelPersonalizationSettingsBJF.xml": "opensim-2023",
    "core/nmsm_core_tests/parse/SimpleXML.xml": "opensim-2023",
    "gcp/patient3_right_foot/GCP_settings.xml": "opensim-2023",
    "jmp/gait2392_walk_free/JMPSettings.xml": "opensim-2023",
    "jmp/rajagopal_isolated_knee/IsolatedReinboltKneeExample.xml": "opensim-2023",
    "jmp/toy_simple_arm/ToySettingsFile.xml": "opensim-2023",
    "mtp/patient3_gait_squat/newMTPSettingsFile.xml": "opensim-2023",
    "ncp/patient3_bilateral_trials1to3/NCPLatest.xml": "opensim-2023",
    "ncp/patient3_bilateral_trials1to3/newNCPSettingsFile.xml": "opensim-2023",
    "ncp/patient3_bilateral_trials1to3/oldNCPSettingsFile.xml": "opensim-2023",
    "treatment/toy_arm/design_optimization/TorqueDrivenDOSettings.xml": "treatment-0.1",
    "treatment/toy_arm/design_optimization/gpopsSettings.xml": "gpops-0.1",
    "treatment/toy_arm/tracking_optimization/TorqueDrivenTOSettings.xml": "treatment-0.1",
    "treatment/toy_arm/tracking_optimization/gpopsSettings.xml": "gpops-0.1",
    "treatment/toy_arm/verification_optimization/TorqueDrivenVOSettings.xml": "treatment-0.1",
    "treatment/toy_arm/verification_optimization/gpopsSettings.xml": "gpops-0.1",
}
#: 2021 parse fixtures of nmsm-core: no model shipped and no <allowable_error> in that schema
FIXTURES_WITHOUT_DATA = {k for k in OLD_FILES if k.startswith("core/")}


def _quiet(function, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


@pytest.mark.shared_data
def test_old_schemas_are_all_found(shared_data: Path) -> None:
    found = {}
    for path in sorted(shared_data.rglob("*.xml")):
        if "MAData" in path.parts:
            continue
        root = parse_settings_xml(path)
        schema = detect_schema(root)
        if schema != "current":
            found[path.relative_to(shared_data).as_posix()] = schema
    assert found == OLD_FILES


@pytest.mark.shared_data
@pytest.mark.parametrize("relative", sorted(OLD_FILES))
def test_every_old_file_upgrades_and_parses_with_current_classes(
    shared_data: Path, tmp_path: Path, relative: str
) -> None:
    path = shared_data / relative
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        doc = read_settings_document(path, check_paths=relative not in FIXTURES_WITHOUT_DATA)
    assert f"old settings schema ({OLD_FILES[relative]}) upgraded" in str(record[0].message)
    assert doc.upgraded_from == OLD_FILES[relative] and doc.root.tag == "NMSMPipelineDocument"
    out = tmp_path / "upgraded.xml"
    result = upgrade_settings_file(path, out)
    assert result.schema == OLD_FILES[relative]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        written = read_settings_document(out, check_paths=False, upgrade=False)  # already current: no upgrade
    assert written.tool == doc.tool and written.version == "1.5.3"
    if relative in FIXTURES_WITHOUT_DATA:
        with pytest.raises(InputError, match="required element <(allowable_error|output_model_file)> is missing"):
            _quiet(settings_from_document, doc)
        return
    settings = _quiet(settings_from_document, doc)
    again = _quiet(settings_from_document, written)
    assert type(settings) is type(again)


@pytest.mark.shared_data
def test_toy_arm_treatment_mapping(shared_data: Path) -> None:
    folder = shared_data / "treatment/toy_arm/verification_optimization"
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        vo = read_tool_settings(folder / "TorqueDrivenVOSettings.xml")
    notes = " ".join(str(w.message) for w in record)
    assert (
        "joint_jerk" in notes and "<joint_jerks_multiple> dropped" in notes and "<initial_states_file> dropped" in notes
    )
    assert vo.tracked_quantities_directory == vo.initial_guess_directory == (folder / "preprocessed").resolve()
    assert vo.trial_name == "arm1" and vo.states_coordinate_list == ("r_elbow_flex",)
    assert vo.torque_controller.coordinate_list == ("r_elbow_flex",)
    assert vo.torque_controller.torque_controls_range_scale_factor == 2.0
    assert (vo.joint_position_range_scale_factor, vo.joint_velocity_range_scale_factor) == (2.0, 1.5)
    assert [(c.type, c.fields.get("coordinate") or c.fields.get("controller")) for c in vo.cost_terms] == [
        ("generalized_coordinate_tracking", "r_elbow_flex"),
        ("controller_tracking", "r_elbow_flex_moment"),
    ]
    assert [(c.type, c.fields["load"], c.fields["max_error"]) for c in vo.constraint_terms] == [
        ("kinetic_consistency", "r_elbow_flex_moment", "0.1")
    ]
    assert vo.optimal_control_solver_settings_file == (folder / "gpopsSettings.xml").resolve()
    to = _quiet(read_tool_settings, shared_data / "treatment/toy_arm/tracking_optimization/TorqueDrivenTOSettings.xml")
    assert [c.type for c in to.cost_terms] == ["generalized_coordinate_tracking", "inverse_dynamics_load_tracking"]
    solver = _quiet(read_tool_settings, folder / "gpopsSettings.xml").gpops
    assert (solver.setup_mesh_phase_intervals, solver.setup_mesh_phase_colpoints_per_Interval) == (5, 10)
    assert solver.setup_mesh_method == "none" and solver.setup_method == "RPM-Integration"
    assert (solver.setup_nlp_max_iterations, solver.setup_nlp_tolerance, solver.setup_derivatives_supplier) == (
        20000,
        1e-3,
        "sparseCD",
    )
    assert solver.setup_mesh_tolerance == 1e-2  # empty in the old file: current default


@pytest.mark.shared_data
def test_old_ncp_moment_term_is_renamed(shared_data: Path) -> None:
    """The early-2023 NCP file names its ID moment term ``inverse_dynamics_joint_moment`` (MTP's
    name; ``newNCPSettingsFile.xml`` has the same 5 N m term as ``moment_tracking``): kept as it
    was, ``nmsm run`` refused it as a cost not allowed in NCP."""
    from nmsm.core.registry import get_registry

    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        ncp = read_tool_settings(shared_data / "ncp/patient3_bilateral_trials1to3/oldNCPSettingsFile.xml")
    assert [c.type for c in ncp.cost_terms] == ["moment_tracking", "activation_tracking", "activation_minimization"]
    assert ncp.cost_terms[0].fields["max_allowable_error"] == "5"
    assert any("inverse_dynamics_joint_moment renamed moment_tracking" in str(w.message) for w in record)
    for term in ncp.cost_terms:
        get_registry().get("cost", term.type, "NCP")  # raises for a cost NCP does not accept


@pytest.mark.shared_data
def test_old_ncp_moment_term_after_a_comment_is_renamed(shared_data: Path, tmp_path: Path) -> None:
    """The rename reads the type as the settings reader does, past a comment inside it."""
    folder = shared_data / "ncp/patient3_bilateral_trials1to3"
    text = (folder / "oldNCPSettingsFile.xml").read_text(encoding="utf-8")
    old = "<type>inverse_dynamics_joint_moment</type>"
    assert old in text
    for entry in folder.iterdir():  # the settings' relative paths, without copying the data
        (tmp_path / entry.name).symlink_to(entry)
    copy = tmp_path / "edited.xml"
    copy.write_text(text.replace(old, "<type><!-- 2023 -->inverse_dynamics_joint_moment</type>", 1), encoding="utf-8")
    ncp = _quiet(read_tool_settings, copy)
    assert [c.type for c in ncp.cost_terms][0] == "moment_tracking"


@pytest.mark.shared_data
def test_personalization_mappings(shared_data: Path) -> None:
    jmp = _quiet(read_tool_settings, shared_data / "jmp/gait2392_walk_free/JMPSettings.xml")
    (task,) = jmp.tasks
    assert task.time_range == (3.067, 4.267) and len(task.marker_names) == 31 and "R.Knee.Lat" not in task.marker_names
    assert task.joints[0].name == "hip_l" and task.joints[0].parent_frame_transformation.translation == (
        True,
        True,
        True,
    )
    assert jmp.max_function_evaluations == 3000 and jmp.function_tolerance == 1e-12

    fixture = _quiet(
        read_settings_document,
        shared_data / "core/nmsm_core_tests/parse/JointModelPersonalizationSettingsBJF.xml",
        check_paths=False,
    )
    tasks = fixture.children(fixture.child(fixture.tool_element, "JMPTaskList"), "JMPTask")
    assert [fixture.integer(t, "index") for t in tasks] == [1, 2, 3]
    joints = fixture.children(fixture.child(tasks[0], "JMPJointSet"), "JMPJoint")
    assert [j.get("name") for j in joints] == ["subtalar_r", "ankle_r"]
    assert fixture.booleans(fixture.child(joints[1], "parent_frame_transformation"), "orientation", count=3) == (
        True,
        True,
        False,
    )
    assert fixture.number(fixture.tool_element, "diff_min_change") == 1e-4

    gcp = _quiet(read_tool_settings, shared_data / "gcp/patient3_right_foot/GCP_settings.xml")
    (foot,) = gcp.contact_surfaces  # the left foot is disabled
    assert foot.hindfoot_body == "calcn_r" and foot.toe_marker == "R.Toe" and gcp.initialize_resting_spring_length
    assert [t.index for t in gcp.tasks] == [1, 2, 3] and gcp.kinematics_filter_cutoff == 10.0
    assert len(gcp.tasks[0].cost_terms) == 6

    folder = shared_data / "ncp/patient3_bilateral_trials1to3"
    ncp = _quiet(read_tool_settings, folder / "NCPLatest.xml")
    assert (
        ncp.data_directory == (folder / "preprocessed").resolve()
        and ncp.mtp_results_directory == (folder / "mtpResults").resolve()
    )
    assert [c.type for c in ncp.cost_terms] == [
        "moment_tracking",
        "activation_tracking",
        "activation_minimization",
        "grouped_activations",
        "grouped_fiber_lengths",
    ]
    assert ncp.cost_terms[0].fields["max_allowable_error"] == "5" and ncp.input_osimx_file is None
    assert len(ncp.activation_muscle_groups) == 36 and ncp.normalized_fiber_length_muscle_groups[0] == "GluteusMaximusL"
    assert [g.muscle_group_name for g in ncp.synergy_groups] == ["right_side", "left_side"]
    mtli = ncp.muscle_tendon_length_initialization
    assert [c.type for c in mtli.cost_terms][-2:] == [
        "grouped_normalized_muscle_fiber_length",
        "grouped_maximum_normalized_muscle_fiber_length",
    ]

    mtp_folder = shared_data / "mtp/patient3_gait_squat"
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        mtp = read_tool_settings(mtp_folder / "newMTPSettingsFile.xml")
    notes = " ".join(str(w.message) for w in record)
    assert "<task_prefixes> dropped" in notes and "<min_allowable_error> dropped" in notes
    assert mtp.data_directory == mtp_folder.resolve() and mtp.synergy_extrapolation.number_of_synergies == 5
    assert mtp.input_osimx_file == (mtp_folder / "results/model_muscleModel.osimx").resolve()
    emg = next(c for c in mtp.tasks[0].cost_terms if c.type == "emg_scale_factor")
    assert "min_allowable_error" not in emg.fields and emg.fields["error_center"] == "0.3"


def test_dropped_elements_are_quoted_in_comments(tmp_path: Path) -> None:
    old = tmp_path / "old.xml"
    old.write_text(
        '<GpopsDocument Version="40000"><GpopsSettings><solver_type>ipopt</solver_type>'
        "<mystery_option>3</mystery_option><collocation_points>2</collocation_points></GpopsSettings></GpopsDocument>"
    )
    result = upgrade_settings_file(old, tmp_path / "new.xml")
    assert any("<mystery_option> dropped: no current equivalent" in n for n in result.notes)
    text = (tmp_path / "new.xml").read_text()
    assert "nmsm upgrade-settings: <mystery_option>3</mystery_option> dropped" in text
    root = etree.parse(str(tmp_path / "new.xml")).getroot()
    assert root.find("OptimalControlSolverSettings/GpopsSettings/setup_mesh_phase_intervals").text == "2"
    solver = read_tool_settings(tmp_path / "new.xml")
    assert solver.gpops.collocation_points == 20 and solver.gpops.setup_nlp_solver == "ipopt"


def test_upgrade_keeps_original_line_numbers(tmp_path: Path) -> None:
    old = tmp_path / "old.xml"
    old.write_text(
        '<GpopsDocument Version="40000">\n<GpopsSettings>\n<solver_tolerance>abc</solver_tolerance>\n</GpopsSettings>\n</GpopsDocument>\n'
    )
    with pytest.raises(InputError) as info:
        _quiet(read_tool_settings, old)
    assert info.value.line == 3 and info.value.element == "<setup_nlp_tolerance>" and info.value.file == str(old)


def test_upgrade_leaves_the_input_tree_alone(shared_data: Path) -> None:
    root = parse_settings_xml(shared_data / "treatment/toy_arm/tracking_optimization/TorqueDrivenTOSettings.xml")
    before = etree.tostring(root)
    upgrade_tree(root, shared_data / "treatment/toy_arm/tracking_optimization/TorqueDrivenTOSettings.xml")
    assert etree.tostring(root) == before


def test_upgrade_settings_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    old = tmp_path / "old.xml"
    old.write_text(
        '<GpopsDocument Version="40000"><GpopsSettings><method>RPM-integration</method></GpopsSettings></GpopsDocument>'
    )
    assert main(["upgrade-settings", str(old), "-o", str(tmp_path / "new.xml")]) == 0
    assert "schema gpops-0.1 -> current" in capsys.readouterr().err
    assert read_tool_settings(tmp_path / "new.xml").gpops.setup_method == "RPM-Integration"
    assert main(["upgrade-settings", str(old), "-o", str(old)]) == 1  # never over the old file
    assert "would overwrite" in capsys.readouterr().err
    assert main(["upgrade-settings", str(tmp_path / "new.xml"), "-o", str(tmp_path / "same.xml")]) == 0
    assert "already uses the current schema" in capsys.readouterr().err


def test_no_upgrade_when_disabled(tmp_path: Path) -> None:
    old = tmp_path / "old.xml"
    old.write_text('<GpopsDocument Version="40000"><GpopsSettings/></GpopsDocument>')
    with pytest.raises(InputError, match="old settings schema \\(gpops-0.1\\)"):
        read_settings_document(old, upgrade=False)

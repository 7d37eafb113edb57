"""The settings document: parsing, version, lookup, typed getters and term specs."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from nmsm.core.term import TermSpec
from nmsm.errors import InputError
from nmsm.io.settings.reader import read_settings_document

DOC = """<NMSMPipelineDocument Version="1.5.0">
  <TrackingOptimizationTool name="default">
    <results_directory/>
    <trial_name> gait_1 </trial_name>
    <states_coordinate_list>hip_flexion_r  knee_angle_r</states_coordinate_list>
    <joint_position_range_scale_factor>2e0</joint_position_range_scale_factor>
    <max_iterations>2e3</max_iterations>
    <normalize_cost_by_term_type>True</normalize_cost_by_term_type>
    <flags>true false true</flags>
    <RCNLTorqueController>
      <coordinate_list>knee_angle_r</coordinate_list>
      <epsilon>1e-4</epsilon>
    </RCNLTorqueController>
    <RCNLCostTermSet>
      <RCNLCostTerm name="Coordinate tracking">
        <is_enabled>true</is_enabled>
        <type>generalized_coordinate_tracking</type>
        <coordinate_list>hip_flexion_r knee_angle_r</coordinate_list>
        <max_allowable_error/>
      </RCNLCostTerm>
    </RCNLCostTermSet>
    <RCNLConstraintTermSet>
      <RCNLConstraintTerm>
        <type>kinetic_consistency</type>
        <load_list>knee_angle_r_moment</load_list>
        <max_error>0.1</max_error>
      </RCNLConstraintTerm>
    </RCNLConstraintTermSet>
  </TrackingOptimizationTool>
</NMSMPipelineDocument>
"""


def _write(tmp_path: Path, text: str, name: str = "settings.xml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_tool_element_and_version(tmp_path: Path) -> None:
    doc = read_settings_document(_write(tmp_path, DOC))
    assert doc.tool == "TrackingOptimizationTool" and doc.tool_element.tag == doc.tool
    assert doc.version == "1.5.0" and doc.upgraded_from is None


def test_typed_getters(tmp_path: Path) -> None:
    doc = read_settings_document(_write(tmp_path, DOC))
    tool = doc.tool_element
    assert doc.text(tool, "trial_name") == "gait_1"
    assert doc.names(tool, "states_coordinate_list") == ("hip_flexion_r", "knee_angle_r")
    assert doc.number(tool, "joint_position_range_scale_factor") == 2.0
    assert doc.integer(tool, "max_iterations") == 2000
    assert doc.booleans(tool, "flags", count=3) == (True, False, True)
    assert doc.number(tool, "absent", 6.0) == 6.0
    assert doc.text(tool, "results_directory", "fallback") == "fallback"  # empty = absent


def test_only_literal_true_and_false(tmp_path: Path) -> None:
    doc = read_settings_document(_write(tmp_path, DOC))
    with pytest.raises(InputError) as info:
        doc.boolean(doc.tool_element, "normalize_cost_by_term_type", False)
    assert info.value.line == 8 and info.value.element == "<normalize_cost_by_term_type>"
    assert "true or false" in info.value.expected


def test_getter_errors_name_file_line_and_element(tmp_path: Path) -> None:
    path = _write(tmp_path, DOC)
    doc = read_settings_document(path)
    tool = doc.tool_element
    with pytest.raises(InputError) as info:
        doc.number(tool, "trial_name")
    assert (info.value.file, info.value.line, info.value.element) == (str(path), 4, "<trial_name>")
    with pytest.raises(InputError, match="required element <input_model_file> is missing"):
        doc.text(tool, "input_model_file", required=True)
    with pytest.raises(InputError, match="2 space-separated true/false values: 3 values given"):
        doc.booleans(tool, "flags", count=2)
    with pytest.raises(InputError, match="not a whole number"):
        doc.integer(doc.child(tool, "RCNLTorqueController"), "epsilon")


def test_missing_required_element_names_a_misspelled_one(tmp_path: Path) -> None:
    path = _write(tmp_path, DOC.replace("<trial_name> gait_1 </trial_name>", "<trial_nmae> gait_1 </trial_nmae>"))
    doc = read_settings_document(path)
    with pytest.raises(InputError, match=r"required element <trial_name> is missing in <TrackingOptimizationTool> "
                                         r"\(found <trial_nmae> at line 4: did you mean <trial_name>\?\)"):
        doc.text(doc.tool_element, "trial_name", required=True)
    with pytest.raises(InputError) as info:  # nothing close: no hint
        doc.text(doc.tool_element, "input_model_file", required=True)
    assert "did you mean" not in str(info.value)


def test_mtp_settings_with_a_misspelled_required_element(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.io.settings.mtp import MuscleTendonPersonalizationSettings

    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    (tmp_path / "CompletedSettingsFiles").mkdir()
    for name in ("UF_Subject_3_reduced_muscles.osim", "preprocessed"):  # what the paths resolve against
        (tmp_path / name).symlink_to(tutorial / name)
    source = tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml"
    path = _write(tmp_path / "CompletedSettingsFiles", source.read_text().replace("coordinate_list>", "coordinate_lst>"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InputError, match=r"<coordinate_list> is missing .*found <coordinate_lst> at line \d+: "
                                             r"did you mean <coordinate_list>\?"):
            MuscleTendonPersonalizationSettings.from_document(read_settings_document(path))


def test_lookup_direct_child_versus_original_depth_first(tmp_path: Path) -> None:
    doc = read_settings_document(_write(tmp_path, DOC))
    tool = doc.tool_element
    assert doc.child(tool, "coordinate_list") is None
    found = doc.find(tool, "coordinate_list")  # depth-first, document order: the controller's
    assert found is not None and found.getparent().tag == "RCNLTorqueController"
    assert doc.find(tool, "trial_name").sourceline == 4


def test_term_specs(tmp_path: Path) -> None:
    path = _write(tmp_path, DOC)
    doc = read_settings_document(path)
    specs = doc.term_specs(doc.tool_element)
    assert [s.kind for s in specs] == ["cost", "constraint"]
    cost, constraint = specs
    assert isinstance(cost, TermSpec) and cost.type == "generalized_coordinate_tracking"
    assert cost.fields["is_enabled"] == "true" and cost.fields["name"] == "Coordinate tracking"
    assert cost.fields["max_allowable_error"] == ""  # kept; the term treats empty as absent
    assert cost.source.file == str(path) and cost.source.line == 15
    assert cost.field_lines["coordinate_list"] == 18
    assert "is_enabled" not in constraint.fields and constraint.fields["max_error"] == "0.1"
    assert [s.type for s in doc.term_specs(doc.tool_element, "constraint")] == ["kinetic_consistency"]


def test_term_without_type(tmp_path: Path) -> None:
    doc = read_settings_document(_write(tmp_path, DOC.replace("<type>kinetic_consistency</type>", "")))
    with pytest.raises(InputError) as info:
        doc.term_specs(doc.tool_element)
    assert info.value.element == "<type>" and info.value.line == 23


def test_malformed_xml_reports_the_line(tmp_path: Path) -> None:
    path = _write(tmp_path, DOC.replace("</trial_name>", "</trial_nam>"))
    with pytest.raises(InputError) as info:
        read_settings_document(path)
    assert info.value.line == 4 and "malformed XML" in info.value.detail and info.value.file == str(path)


def test_unknown_tool_element(tmp_path: Path) -> None:
    path = _write(tmp_path, '<NMSMPipelineDocument Version="1.5.0">\n  <SomeTool/>\n</NMSMPipelineDocument>')
    with pytest.raises(InputError) as info:
        read_settings_document(path)
    assert info.value.line == 2 and info.value.element == "<SomeTool>"
    assert "<JointModelPersonalizationTool>" in info.value.expected


def test_unknown_root_and_two_tools(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="root element is <Settings>"):
        read_settings_document(_write(tmp_path, "<Settings/>"))
    two = '<NMSMPipelineDocument Version="1.5.0"><TrackingOptimizationTool/><DesignOptimizationTool/></NMSMPipelineDocument>'
    with pytest.raises(InputError, match="holds 2 elements"):
        read_settings_document(_write(tmp_path, two))


@pytest.mark.parametrize("relative,tool,hint", [
    ("jmp/uf_subject3_tutorial/IKSettingsFiles/IKSettingsHips.xml", "InverseKinematicsTool", "'nmsm ik MODEL --ik-settings FILE'"),
    ("preprocessing/uf_subject3_tutorial/input_data/IDSettings.xml", "InverseDynamicsTool", "'nmsm id MODEL MOTION"),
    ("preprocessing/uf_subject3_tutorial/input_data/MASettings.xml", "AnalyzeTool", "'nmsm muscle-analysis MODEL MOTION"),
    ("moco2d/referenceGRF.xml", "ExternalLoads", "as --external-loads"),
    ("jmp/uf_subject3_tutorial/ScaleSettings.xml", "ScaleTool", "nmsm has no scaling tool"),
])
def test_opensim_tool_file_given_to_run(shared_data: Path, relative: str, tool: str, hint: str) -> None:
    """An OpenSim tool's own settings (the tutorials ship IK/ID/Analyze/Scale files and external
    loads next to NMSM's) is named as such, with the nmsm command that reads it."""
    from nmsm.tools.dispatch import run_settings_file

    with pytest.raises(InputError) as info:
        run_settings_file(shared_data / relative)
    assert info.value.element == f"<{tool}>" and info.value.file == str(shared_data / relative)
    assert f"<OpenSimDocument> holding <{tool}>: an OpenSim file" in info.value.detail
    assert hint in info.value.expected


def test_solver_settings_given_to_run(shared_data: Path) -> None:
    from nmsm.tools.dispatch import run_settings_file

    path = shared_data / "treatment/synergy_kick_tutorial/gpopsSettings.xml"
    with pytest.raises(InputError, match="solver settings of a treatment optimization") as info:
        run_settings_file(path)
    assert "<optimal_control_solver_settings_file>" in info.value.expected


def test_version_major_error_minor_warning(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="version 2.0.0 is not supported"):
        read_settings_document(_write(tmp_path, DOC.replace('Version="1.5.0"', 'Version="2.0.0"')))
    with pytest.warns(UserWarning, match="minor version"):
        read_settings_document(_write(tmp_path, DOC.replace('Version="1.5.0"', 'Version="1.4.2"')))
    with pytest.raises(InputError, match="Version attribute"):
        read_settings_document(_write(tmp_path, DOC.replace(' Version="1.5.0"', "")))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read_settings_document(_write(tmp_path, DOC.replace('Version="1.5.0"', 'Version="1.5.3"')))


def test_repeated_scalar_element_is_an_error(tmp_path: Path) -> None:
    doc = read_settings_document(
        _write(
            tmp_path,
            DOC.replace("<trial_name> gait_1 </trial_name>", "<trial_name>a</trial_name>\n<trial_name>b</trial_name>"),
        )
    )
    with pytest.raises(InputError, match="appears 2 times"):
        doc.text(doc.tool_element, "trial_name")


def test_unreadable_settings_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="cannot read settings file"):
        read_settings_document(tmp_path / "none.xml")

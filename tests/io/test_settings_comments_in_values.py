"""Comments inside a settings value are not part of it and hide none of it.

lxml's ``element.text`` stops at the first comment: ``<v_max_factor><!-- default 10 -->15
</v_max_factor>`` was read as empty (default 10, with an "empty element" warning),
``<is_enabled><!-- on -->true</is_enabled>`` as absent (false), a list lost every name after a
comment, and a comment in a term field was "child elements"."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np

from nmsm.io.settings.reader import read_settings_document
from nmsm.io.xml_input import element_text, set_element_text

DOC = """<NMSMPipelineDocument Version="1.5.0">
  <TrackingOptimizationTool name="default">
    <states_coordinate_list>hip_flexion_r <!-- the knee next --> knee_angle_r
      <!-- and the ankle -->ankle_angle_r</states_coordinate_list>
    <max_iterations><!-- about a minute -->150</max_iterations>
    <enabled><!-- on for now -->true</enabled>
    <RCNLCostTermSet>
      <RCNLCostTerm>
        <type>generalized_coordinate_tracking</type>
        <max_allowable_error><!-- rad -->0.25</max_allowable_error>
      </RCNLCostTerm>
    </RCNLCostTermSet>
  </TrackingOptimizationTool>
</NMSMPipelineDocument>
"""


def test_comments_inside_values_are_skipped(tmp_path: Path) -> None:
    path = tmp_path / "settings.xml"
    path.write_text(DOC)
    doc = read_settings_document(path, check_paths=False)
    tool = doc.tool_element
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "empty element treated as absent"
        assert doc.names(tool, "states_coordinate_list") == ("hip_flexion_r", "knee_angle_r", "ankle_angle_r")
        assert doc.integer(tool, "max_iterations", 1000) == 150
        assert doc.boolean(tool, "enabled", False) is True
    (term,) = doc.term_specs(tool)
    assert term.fields["max_allowable_error"] == "0.25"


def test_setting_the_text_replaces_the_comment_tails() -> None:
    from lxml import etree

    element = etree.fromstring("<input_model_file><!-- old -->old.osim</input_model_file>")
    set_element_text(element, "/new/model.osim")
    assert element_text(element) == "/new/model.osim"
    assert b"<!-- old -->" in etree.tostring(element)


def test_mtp_tutorial_with_commented_values_runs_as_without(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.io.storage import read_storage
    from nmsm.tools.mtp.run import run_settings

    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    shutil.copytree(tutorial / "preprocessed", tmp_path / "preprocessed")
    shutil.copy(tutorial / "UF_Subject_3_reduced_muscles.osim", tmp_path)
    text = (tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml").read_text()
    # a short run: no MTLI, the task's first two cost terms
    text = text.replace("<is_enabled>true</is_enabled>\n\t\t\t<!--Directory", "<is_enabled>false</is_enabled>\n\t\t\t<!--Directory")
    results = {}
    for name, quirky in (("plain", text), ("commented", text.replace(
            "<coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>",
            "<coordinate_list>hip_flexion_r <!-- knee --> knee_angle_r ankle_angle_r</coordinate_list>").replace(
            "<max_allowable_error>2.5</max_allowable_error>",
            "<max_allowable_error><!-- N m -->2.5</max_allowable_error>"))):
        assert quirky.count("<!-- ") >= (2 if name == "commented" else 0)
        settings = tmp_path / f"{name}.xml"
        settings.write_text(quirky.replace("<results_directory>MTPResultsV3</results_directory>",
                                           f"<results_directory>{name}</results_directory>"))
        run_settings(settings)
        results[name] = read_storage(tmp_path / name / "modelMoments" / "gait_1_modelMoments.sto")
    assert results["commented"].labels == results["plain"].labels == (
        "hip_flexion_r", "knee_angle_r", "ankle_angle_r")
    np.testing.assert_array_equal(results["commented"].data, results["plain"].data)

"""Toy arm (known answer): JMP recovers simple_arm.osim's elbow frame from both perturbed models."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from lxml import etree

from nmsm.core.convergence import read_convergence_table
from nmsm.cli import main
from nmsm.model import load_model
from nmsm.plots.jmp import is_jmp_results, plot_jmp_results
from nmsm.tools.jmp.run import LOG_FILE, REPORT_FILE, RESULTS_FILE, run_settings

TOY = "jmp/toy_simple_arm"
FRAME = "/jointset/r_elbow/r_humerus_offset"


def _settings(shared_data, tmp_path, model: str, translation: str, orientation: str):
    """The toy settings file with another model and flags, written next to nothing shared."""
    tree = etree.parse(str(shared_data / TOY / "ToySettingsFile.xml"))
    tool = tree.getroot().find("JointModelPersonalizationTool")
    tool.find("input_model_file").text = str(shared_data / TOY / model)
    task = tool.find("JMPTaskList/JMPTask")
    task.find("marker_file_name").text = str(shared_data / TOY / "simple_arm.trc")
    frame = task.find(".//JMPJoint/parent_frame_transformation")
    frame.find("translation").text = translation
    frame.find("orientation").text = orientation
    path = tmp_path / "toy.xml"
    tree.write(str(path))
    return path


def test_translated_away_recovers_the_translation(shared_data, tmp_path):
    """The shared settings file as it is (old schema), results elsewhere."""
    truth = load_model(shared_data / TOY / "simple_arm.osim").frames[FRAME]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # old schema upgraded
        run = run_settings(shared_data / TOY / "ToySettingsFile.xml", results_directory=tmp_path, quiet=True)
    result = load_model(run.output_model).frames[FRAME]
    assert abs(result.translation[0] - truth.translation[0]) <= 1e-4  # 0.1 mm
    np.testing.assert_array_equal(result.translation[1:], truth.translation[1:])
    np.testing.assert_array_equal(result.orientation, truth.orientation)
    assert run.tasks[0].after.marker_rms() < 1e-5  # float32 markers: "perfect (error < 1e-5 m)"
    for name in (REPORT_FILE, RESULTS_FILE, LOG_FILE, "ToySettingsFile.xml", "translation_result_from_xml.osim",
                 "task1_Right_Elbow/ik_after.mot", "task1_Right_Elbow/marker_errors_before.sto"):
        assert (tmp_path / name).is_file(), name
    assert not list(tmp_path.glob(".staging-*"))
    assert is_jmp_results(tmp_path)
    figures = plot_jmp_results(tmp_path)
    assert [f.name for f in figures] == ["jmp_task1_Right_Elbow.png", "jmp_summary.png", "convergence.png"]
    history = read_convergence_table(tmp_path / "convergence.tsv")["task1_Right_Elbow"]
    assert history.n_iterations >= 2 and history.cost[-1] == pytest.approx(run.tasks[0].solution.cost)
    assert history.cost[-1] < history.cost[0] and history.violation is None
    assert all(f.stat().st_size > 10_000 for f in figures)


def test_oriented_away_recovers_the_orientation(shared_data, tmp_path):
    truth = load_model(shared_data / TOY / "simple_arm.osim").frames[FRAME]
    settings = _settings(shared_data, tmp_path, "simple_arm_oriented_away.osim", "false false false",
                         "true false false")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_settings(settings, results_directory=tmp_path / "out", quiet=True)
    result = load_model(run.output_model).frames[FRAME]
    assert np.degrees(abs(result.orientation[0] - truth.orientation[0])) <= 0.01
    assert run.tasks[0].design.variables[0].initial == pytest.approx(0.5)  # it started 28.6 deg away
    np.testing.assert_array_equal(result.translation, truth.translation)


def test_nmsm_run_dispatches_and_output_loads_in_opensim(shared_data, tmp_path, bridge):
    settings = _settings(shared_data, tmp_path, "simple_arm_translated_away.osim", "true false false",
                         "false false false")
    tree = etree.parse(str(settings))
    tree.getroot().find("JointModelPersonalizationTool/results_directory").text = str(tmp_path / "cli")
    tree.write(str(settings))
    assert main(["run", str(settings)]) == 0
    output = tmp_path / "cli" / "translation_result_from_xml.osim"
    info = bridge.call("model_info", path=str(output))
    assert info["coordinates"] == ["r_elbow_flex"]
    assert abs(load_model(output).frames[FRAME].translation[0] - 0.0061) <= 1e-4

"""Bad JMP input: names that do not exist, a read-only results folder."""

from __future__ import annotations

import warnings

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case
from nmsm.tools.jmp.run import run_settings


@pytest.fixture
def case(tmp_path):
    return make_synthetic_jmp_case(tmp_path, noise=0.0, duration=0.3)


def _edit(case, change) -> None:
    tree = etree.parse(str(case.settings_file))
    change(tree.getroot().find("JointModelPersonalizationTool/JMPTaskList/JMPTask"))
    tree.write(str(case.settings_file))


def test_unknown_joint(case):
    _edit(case, lambda task: task.find("JMPJointSet/JMPJoint").set("name", "knee_x"))
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, quiet=True)
    message = str(info.value)
    assert str(case.settings_file) in message and "knee_x" in message and "close matches: knee" in message
    assert "JMPJoint" in message


def test_unknown_body(case):
    def add_body(task):
        body = etree.SubElement(etree.SubElement(task, "JMPBodySet"), "JMPBody", name="femur")
        etree.SubElement(body, "scale_body").text = "true"
    _edit(case, add_body)
    with pytest.raises(InputError, match="body 'femur' is not in the model"):
        run_settings(case.settings_file, quiet=True)


def test_marker_missing_from_the_marker_file(case):
    def rename(task):
        names = task.find("marker_names")
        names.text = names.text.replace("HEEL", "HEEL_X")
    _edit(case, rename)
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, quiet=True)
    assert "HEEL_X" in str(info.value) and "<marker_names>" in str(info.value)


def test_marker_missing_from_the_model(case, tmp_path):
    # a marker present in the file but not in the model
    text = case.marker_file.read_text().replace("\tTOE\t", "\tTOE2\t")
    case.marker_file.write_text(text)

    def rename(task):
        names = task.find("marker_names")
        names.text = names.text.replace("TOE", "TOE2")
    _edit(case, rename)
    with pytest.raises(InputError, match="marker 'TOE2' is not in the model"):
        run_settings(case.settings_file, quiet=True)


def test_results_never_overwrite_an_input(case):
    """output_model_file naming the input model, results next to it: refused, input intact."""
    tree = etree.parse(str(case.settings_file))
    tool = tree.getroot().find("JointModelPersonalizationTool")
    tool.find("output_model_file").text = case.nominal_model.name
    tool.find("results_directory").text = "."
    tree.write(str(case.settings_file))
    before = case.nominal_model.read_bytes()
    with pytest.raises(InputError, match="overwrite an input"):
        run_settings(case.settings_file, quiet=True)
    assert case.nominal_model.read_bytes() == before


def test_time_range_beyond_the_markers_warns(case):
    """jmp05: <time_range> 0 7 on 0-0.3 s of markers is cut to the data, and the warning says so."""
    _edit(case, lambda task: etree.SubElement(task, "time_range").__setattr__("text", "0 7"))
    with pytest.warns(UserWarning) as record:
        run_settings(case.settings_file, quiet=True)
    messages = [str(w.message) for w in record if "<time_range>" in str(w.message)]
    assert len(messages) == 1
    message = messages[0]
    assert message.startswith(f"{case.settings_file}: <time_range> 0-7 s reaches beyond the marker data")
    assert "markers.trc (0-0.3 s); using its frames in 0-0.3 s" in message


def test_time_range_inside_the_markers_is_silent(case):
    _edit(case, lambda task: etree.SubElement(task, "time_range").__setattr__("text", "0 0.3"))
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        run_settings(case.settings_file, quiet=True)
    assert not [w for w in record if "<time_range>" in str(w.message)]

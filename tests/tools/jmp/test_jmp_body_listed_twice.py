"""A <JMPBody> listed twice in one task is one error at the second one (fuzz audit: it was a
ValueError traceback, "scale of body 'pelvis' is already parameterized"), as a <JMPJoint>
listed twice already is."""

from __future__ import annotations

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case
from nmsm.model.osim import load_model
from nmsm.tools.jmp.run import run_settings


def test_body_listed_twice_is_one_error_at_its_line(tmp_path) -> None:
    case = make_synthetic_jmp_case(tmp_path, noise=0.0, duration=0.3)
    body_name = next(name for name in load_model(case.nominal_model).bodies if name != "ground")
    tree = etree.parse(str(case.settings_file))
    task = tree.getroot().find("JointModelPersonalizationTool/JMPTaskList/JMPTask")
    bodies = etree.SubElement(task, "JMPBodySet")
    for _ in range(2):
        body = etree.SubElement(bodies, "JMPBody", name=body_name)
        etree.SubElement(body, "scale_body").text = "true"
    tree.write(str(case.settings_file))
    second_line = etree.parse(str(case.settings_file)).getroot().findall(".//JMPBody")[1].sourceline
    results = tmp_path / "results"
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, results_directory=results, quiet=True)
    assert (info.value.file, info.value.line) == (str(case.settings_file), second_line)
    assert info.value.element == f'<JMPBody name="{body_name}">'
    assert f"body '{body_name}' is listed twice" in str(info.value)
    assert "each body once per task" in str(info.value)
    assert not results.exists()

"""``nmsm print-xml``: templates built from the settings classes parse back with their defaults."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.cli import main
from nmsm.io.settings import SETTINGS_CLASSES, TOOL_CODES, read_tool_settings
from nmsm.io.settings.schema import settings_fields
from nmsm.io.settings.solver import GpopsSettings
from nmsm.io.settings.template import format_template, format_value


def _defaults_match(obj: object) -> None:
    """Every field that has a parser default carries it (templates show the defaults)."""
    for attribute, spec in settings_fields(type(obj)):
        value = getattr(obj, attribute.name)
        if spec.kind == "block" and value is not None:
            _defaults_match(value)
        elif spec.kind == "blocks":
            for item in value:
                _defaults_match(item)
        elif (
            spec.kind in ("number", "integer", "boolean", "text", "names", "numbers", "booleans")
            and spec.default is not None
        ):
            if spec.default == () and spec.example:
                continue
            assert value == spec.default, (type(obj).__name__, attribute.name, value, spec.default)


@pytest.mark.parametrize("code", ["jmp", "mtp", "ncp", "gcp", "to", "vo", "do", "solver"])
def test_template_parses_back_without_warnings(code: str, tmp_path: Path) -> None:
    path = tmp_path / f"{code}.xml"
    path.write_text(format_template(TOOL_CODES[code]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        settings = read_tool_settings(path, check_paths=False)
    assert type(settings) is SETTINGS_CLASSES[TOOL_CODES[code]]
    _defaults_match(settings)


def test_template_documents_every_element() -> None:
    text = format_template("MuscleTendonPersonalizationTool")
    root = etree.fromstring(text.split("\n", 1)[1].encode())
    tool = root[0]
    comments = [c.text for c in tool.iter(etree.Comment)]
    assert any("Maximum iterations of the optimizer. default 10000." in c for c in comments)
    assert tool.findtext("max_iterations") == "10000" and tool.findtext("v_max_factor") == "10"
    assert tool.find("MuscleTendonLengthInitialization/maximum_muscle_stress").text == "610000"
    assert tool.find("MTPTaskList/MTPTask/RCNLCostTermSet/RCNLCostTerm/type").text == "inverse_dynamics_joint_moment"
    assert tool.find("diff_min_change") is None  # read but ignored by MTP: not in the template


def test_treatment_template_shows_the_synergy_controller_commented_out() -> None:
    text = format_template("DesignOptimizationTool")
    assert "<RCNLSynergyController>" in text and "remove the comment marks" in text
    root = etree.fromstring(text.split("\n", 1)[1].encode())
    assert root[0].find("RCNLSynergyController") is None and root[0].find("RCNLTorqueController") is not None
    assert root[0].find("RCNLParameterTermSet/RCNLParameterTerm/type").text == "belt_speed"


def test_format_value() -> None:
    assert format_value(True) == "true" and format_value((False, True)) == "false true"
    assert format_value(610000.0) == "610000" and format_value(1e-6) == "1e-06" and format_value(("a", "b")) == "a b"


def test_print_xml_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["print-xml", "gcp"]) == 0
    out = capsys.readouterr().out
    assert "<GroundContactPersonalizationTool>" in out and "<grid_height>15</grid_height>" in out
    assert main(["print-xml", "solver", "-o", str(tmp_path / "solver.xml")]) == 0
    solver = read_tool_settings(tmp_path / "solver.xml")
    assert solver.gpops == GpopsSettings()  # every element at its parser default
    assert solver.gpops.setup_mesh_phase_intervals == 6 and solver.gpops.integral_bound == 1.0
    with pytest.raises(SystemExit):
        main(["print-xml", "xyz"])

"""Treatment settings that are wrong are refused when read, naming file, line and element.

Audit cases c14 (0.1.0 ``<type_of_controller>``), c21 (``<final_time_range>``) and c08
(misspelled controller element); the files are the shared tutorials' with one edit.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.settings import read_settings_document, read_tool_settings

TOY_TO = Path("treatment/toy_arm/tracking_optimization/TorqueDrivenTOSettings.xml")
KICK_DO = Path("treatment/torque_kick_tutorial/CompletedSettingsFiles/TorqueDOSettingsV3.xml")


def _edited(shared: Path, relative: Path, tmp: Path, old: str, new: str) -> Path:
    text = (shared / relative).read_text()
    assert old in text
    path = tmp / relative.name
    path.write_text(text.replace(old, new))
    return path


def _line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), 1) if text in line)


@pytest.mark.shared_data
@pytest.mark.parametrize("value, hint", [("synergy_drivn", "did you mean 'synergy_driven'?"),
                                         ("muscle_driven", ""), ("", "")])
def test_unknown_old_controller_type_is_an_error(shared_data: Path, tmp_path: Path, value: str, hint: str) -> None:
    old = "<type_of_controller>torque_driven</type_of_controller>"
    path = _edited(shared_data, TOY_TO, tmp_path, old, f"<type_of_controller>{value}</type_of_controller>")
    line = _line_of(path, "<type_of_controller>")
    with pytest.raises(InputError) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_settings_document(path, check_paths=False)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}: <type_of_controller>: ")
    assert (f"'{value}' is not a controller type" if value else "empty controller type") in message
    assert hint in message and message.endswith("(expected torque_driven or synergy_driven)")


@pytest.mark.shared_data
def test_old_controller_types_still_upgrade(shared_data: Path, tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = read_settings_document(shared_data / TOY_TO, check_paths=False)
        assert doc.tool_element.find("RCNLTorqueController") is not None
        old = "<type_of_controller>torque_driven</type_of_controller>"
        path = _edited(shared_data, TOY_TO, tmp_path, old, "<type_of_controller>synergy_driven</type_of_controller>")
        doc = read_settings_document(path, check_paths=False)
    assert doc.tool_element.find("RCNLSynergyController") is not None


@pytest.mark.shared_data
@pytest.mark.parametrize("bounds", ["-0.1 0.36", "0 0.36"])
def test_final_time_range_must_be_positive(shared_data: Path, tmp_path: Path, bounds: str) -> None:
    old = "<final_time_range>0.26 0.36</final_time_range>"
    path = _edited(shared_data, KICK_DO, tmp_path, old, f"<final_time_range>{bounds}</final_time_range>")
    line = _line_of(path, "<final_time_range>")
    with pytest.raises(InputError) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_tool_settings(path, check_paths=False)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}: <final_time_range>: final time bounds {bounds}: ")
    assert message.endswith("(expected 0 < lower <= upper (s))")


@pytest.mark.shared_data
def test_misspelled_controller_element_is_named(shared_data: Path, tmp_path: Path) -> None:
    path = _edited(shared_data, KICK_DO, tmp_path, "RCNLTorqueController>", "RCNLTorqueControler>")
    line = _line_of(path, "<RCNLTorqueControler>")
    with pytest.raises(InputError) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        read_tool_settings(path, check_paths=False)
    assert re.search(rf"no controller \(found <RCNLTorqueControler> at line {line}: did you mean "
                     r"<RCNLTorqueController>\?\)", str(info.value))

"""A treatment settings file naming a surrogate data folder that does not exist stops with an
``InputError`` that prints the ``nmsm surrogate`` command making it from the settings' own
model, motion and coordinates (issue 24, item 5)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from nmsm.errors import InputError

TUTORIAL = "treatment/synergy_kick_tutorial"


def _settings_with_missing_folder(shared_data: Path, tmp_path: Path) -> Path:
    """SynergyTOSettingsV1 with absolute input paths and a surrogate folder that does not exist."""
    root = shared_data / TUTORIAL
    text = (root / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml").read_text(encoding="utf-8")
    for element, value in (("initial_guess_directory", root / "ncpResults"),
                           ("tracked_quantities_directory", root / "preprocessed"),
                           ("input_model_file", root / "KickingModel.osim"),
                           ("input_osimx_file", root / "ncpResults" / "KickingModel_ncp.osimx"),
                           ("optimal_control_solver_settings_file", root / "gpopsSettings.xml"),
                           ("surrogate_model_data_directory", "samples/missingSurrogateData")):
        text, n = re.subn(f"<{element}>[^<]*</{element}>", f"<{element}>{value}</{element}>", text)
        assert n == 1, element
    path = tmp_path / "SynergyTO.xml"
    path.write_text(text, encoding="utf-8")
    return path


def test_missing_surrogate_folder_prints_the_command_that_makes_it(shared_data, tmp_path):
    from nmsm.cli import build_parser
    from nmsm.tools.treatment.run import load_settings

    settings = _settings_with_missing_folder(shared_data, tmp_path)
    with pytest.raises(InputError) as caught:
        load_settings(settings)
    error = caught.value
    assert error.file == str(settings) and error.element == "<surrogate_model_data_directory>"
    message = str(error)
    command = next(line.strip() for line in message.splitlines() if line.strip().startswith("nmsm surrogate"))
    words = shlex.split(command)
    args = build_parser().parse_args(words[1:])
    root = shared_data / TUTORIAL
    assert Path(args.model) == (root / "KickingModel.osim").resolve()
    assert Path(args.motion) == (root / "preprocessed" / "IKData" / "drive_kick1.sto").resolve()
    assert args.coordinates == ["hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r",
                                "ankle_angle_r", "subtalar_angle_r"]
    assert Path(args.write_samples) == (tmp_path / "samples" / "missingSurrogateData").resolve()
    assert Path(args.output) == (tmp_path / "surrogateMuscles.json").resolve()
    assert args.degree == 5 and args.settings is None


def test_existing_surrogate_folder_passes_the_check(shared_data, tmp_path):
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.tools.treatment.surrogate_folder import check_surrogate_data_folder

    settings = _settings_with_missing_folder(shared_data, tmp_path)
    existing = shared_data / TUTORIAL / "surrogateData"
    settings.write_text(settings.read_text(encoding="utf-8").replace("samples/missingSurrogateData", str(existing)),
                        encoding="utf-8")
    check_surrogate_data_folder(read_settings_document(settings))

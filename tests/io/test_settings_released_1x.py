"""Settings of released 1.x versions: GCP's ``<toe_joint>`` / ``<toe_coordinate>`` (1.0.x, and
beside ``<hindfoot_body>`` in 1.1.0 files) are read, checked against the model, and refused
only where they contradict it. Built from the shared tutorial's GCPSettingsV1.xml."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.settings import GroundContactPersonalizationSettings, read_settings_document, read_tool_settings
from nmsm.cli import main

TUTORIAL = "gcp/uf_subject3_tutorial"


def released_gcp(shared_data: Path, tmp_path: Path, version: str, edit) -> Path:
    """The tutorial's GCPSettingsV1.xml as release ``version`` wrote it (``edit(surface)``),
    in a copy of the tutorial layout (data and model linked)."""
    source = shared_data / TUTORIAL
    (tmp_path / "preprocessed").symlink_to(source / "preprocessed", target_is_directory=True)
    (tmp_path / "bodyModel.osim").symlink_to(source / "bodyModel.osim")
    (tmp_path / "CompletedSettingsFiles").mkdir()
    tree = etree.parse(str(source / "CompletedSettingsFiles" / "GCPSettingsV1.xml"))
    root = tree.getroot()
    root.set("Version", version)
    edit(root.find("GroundContactPersonalizationTool/GCPContactSurfaceSet/GCPContactSurface"))
    path = tmp_path / "CompletedSettingsFiles" / "GCPSettings.xml"
    tree.write(str(path))
    return path


def _add_after_hindfoot(surface, tag: str, text: str) -> None:
    hindfoot = surface.find("hindfoot_body")
    element = etree.Element(tag)
    element.text = text
    hindfoot.addnext(element)


def _as_1_0(surface, joint: str = "mtp_r", coordinate: str = "mtp_angle_r") -> None:
    """1.0.x: <toe_coordinate> and <toe_joint> where 1.1.0 writes <hindfoot_body>."""
    hindfoot = surface.find("hindfoot_body")
    for tag, text in (("toe_joint", joint), ("toe_coordinate", coordinate)):
        element = etree.Element(tag)
        element.text = text
        hindfoot.addnext(element)
    surface.remove(hindfoot)


def _read(path: Path):
    with pytest.warns(UserWarning) as record:
        settings = read_tool_settings(path)
    return settings, [str(w.message) for w in record]


@pytest.mark.shared_data
def test_toe_joint_beside_hindfoot_body_of_a_1_1_0_file(shared_data: Path, tmp_path: Path) -> None:
    """Refused before ("<toe_joint> is from the old GCP schema"); the original reads it."""
    path = released_gcp(shared_data, tmp_path, "1.1.0", lambda s: _add_after_hindfoot(s, "toe_joint", "mtp_r"))
    settings, messages = _read(path)
    assert isinstance(settings, GroundContactPersonalizationSettings)
    assert [s.hindfoot_body for s in settings.contact_surfaces] == ["calcn_r"]
    about = [m for m in messages if "<toe_joint>" in m]
    assert len(about) == 1 and 'Version="1.1.0"' in about[0] and "mtp_r -> calcn_r" in about[0]


@pytest.mark.shared_data
def test_toe_joint_and_coordinate_of_a_1_0_0_file_give_the_hindfoot_body(shared_data: Path, tmp_path: Path) -> None:
    path = released_gcp(shared_data, tmp_path, "1.0.0", _as_1_0)
    settings, messages = _read(path)
    assert [s.hindfoot_body for s in settings.contact_surfaces] == ["calcn_r"]
    assert len([m for m in messages if "<toe_joint>" in m]) == 1
    assert len([m for m in messages if "<toe_coordinate>" in m and "mtp_angle_r -> calcn_r" in m]) == 1


@pytest.mark.shared_data
@pytest.mark.parametrize(("edit", "element", "message"), [
    (lambda s: (s.find("hindfoot_body").__setattr__("text", "calcn_l"), _add_after_hindfoot(s, "toe_joint", "mtp_r")),
     "<hindfoot_body>", "<hindfoot_body>calcn_l</hindfoot_body> contradicts <toe_joint>mtp_r</toe_joint>, whose "
                        "parent body in the model is 'calcn_r'"),
    (lambda s: _as_1_0(s, coordinate="mtp_angle_l"), "<toe_coordinate>",
     "<toe_coordinate>mtp_angle_l</toe_coordinate> belongs to joint 'mtp_l', not to <toe_joint>mtp_r</toe_joint>"),
    (lambda s: _as_1_0(s, joint="mtp"), "<toe_joint>", "'mtp' is not a joint of the input model"),
    (lambda s: _add_after_hindfoot(s, "toes_coordinate", "toe_angle_r"), "<toes_coordinate>",
     "'toe_angle_r' is not a coordinate of the input model"),
])
def test_toe_elements_contradicting_the_model_or_the_file_are_refused(shared_data: Path, tmp_path: Path, edit,
                                                                     element: str, message: str) -> None:
    path = released_gcp(shared_data, tmp_path, "1.1.0", edit)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InputError) as info:
            read_settings_document(path)
    error = info.value
    assert error.file == str(path) and error.element == element and error.line is not None
    assert message in error.detail


@pytest.mark.shared_data
def test_upgrade_settings_writes_the_hindfoot_body(shared_data: Path, tmp_path: Path, capsys) -> None:
    path = released_gcp(shared_data, tmp_path, "1.0.0", _as_1_0)
    out = path.with_name("GCPSettings_upgraded.xml")
    assert main(["upgrade-settings", str(path), "-o", str(out)]) == 0
    printed = capsys.readouterr().err
    assert "elements of an earlier 1.x release -> current" in printed and "<toe_joint>" in printed
    assert "earlier 1.x release translated" in out.read_text().splitlines()[0]
    surface = etree.parse(str(out)).getroot().find(".//GCPContactSurface")
    assert surface.findtext("hindfoot_body") == "calcn_r"
    assert surface.find("toe_joint") is None and surface.find("toe_coordinate") is None


@pytest.mark.shared_data
def test_an_element_without_effect_is_named_once(shared_data: Path, tmp_path: Path) -> None:
    """The 1.1.0 tutorial's MTP settings carry <MTPSynergyExtrapolation><task_prefixes>, which the
    current original does not read: one warning naming it and its release (it was an "unknown
    element" warning)."""
    source = shared_data / "mtp" / "uf_subject3_tutorial"
    for name in ("preprocessed", "passive_moment_data"):
        (tmp_path / name).symlink_to(source / name, target_is_directory=True)
    (tmp_path / "UF_Subject_3_reduced_muscles.osim").symlink_to(source / "UF_Subject_3_reduced_muscles.osim")
    tree = etree.parse(str(source / "CompletedSettingsFiles" / "MTPSettingsV1.xml"))
    tree.getroot().set("Version", "1.1.0")
    synx = tree.getroot().find("MuscleTendonPersonalizationTool/MTPSynergyExtrapolation")
    prefixes = etree.SubElement(synx, "task_prefixes")
    prefixes.text = "gait_1"
    path = tmp_path / "MTPSettings.xml"
    tree.write(str(path))
    settings, messages = _read(path)
    assert settings.synergy_extrapolation is not None
    about = [m for m in messages if "task_prefixes" in m]
    assert len(about) == 1, about
    assert "written by NMSM Pipeline 1.1" in about[0] and "no effect" in about[0] and "unknown" not in about[0]

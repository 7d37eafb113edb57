""".osimx entries that appear twice, or a contact surface without springs (fuzz audit of
.osimx files). Before: a copied ``<RCNLContactSurface>`` was accepted by ``nmsm export`` and
Tracking Optimization (that foot pushed twice, silently); a copied ``<GCPSpring>`` likewise;
a copied ``<RCNLSynergy>`` made TO report "5 synergy rows for 10 synergies" about
synergyWeights.sto; a surface without ``<GCPSpringSet>`` made TO fail with a CasADi "Slice ...
out of bounds" while building a term. Now each is one error naming the .osimx and the line."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import pytest

from nmsm.cli import main
from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
from nmsm.errors import InputError
from nmsm.io.osimx import (
    GcpSpring,
    OsimxContactSurface,
    OsimxModel,
    OsimxSynergy,
    check_contact_surfaces,
    format_osimx,
    parse_osimx,
    read_osimx,
)


def _surface(body: str, springs: int = 2) -> OsimxContactSurface:
    return OsimxContactSurface(
        is_left_foot=body.endswith("_l"), belt_speed=0.0, force_columns=("fx", "fy", "fz"),
        moment_columns=("mx", "my", "mz"), electrical_center_columns=("px", "py", "pz"), hindfoot_body=body,
        toe_marker="T", medial_marker="M", lateral_marker="L", heel_marker="H", midfoot_superior_marker="S",
        resting_spring_length=0.01, dynamic_friction_coefficient=0.6, viscous_friction_coefficient=0.0,
        damping_factor=0.3, latching_velocity=0.05,
        springs=tuple(GcpSpring(f"spring_marker_{i}", body, (0.01 * i, 0.0, 0.0), 4000.0)
                      for i in range(1, springs + 1)),
    )


def _text(*surfaces: OsimxContactSurface, synergies=(OsimxSynergy("RightLeg", 5),)) -> str:
    return format_osimx(OsimxModel(name="m", associated_osim_model="m.osim", contact_surfaces=surfaces,
                                   synergies=tuple(synergies)))


def _line(text: str, needle: str, occurrence: int = 1) -> int:
    lines = [i for i, line in enumerate(text.splitlines(), start=1) if needle in line]
    return lines[occurrence - 1]


def test_a_spring_name_twice_in_one_surface_is_an_error_at_the_second() -> None:
    text = _text(_surface("calcn_r")).replace('name="spring_marker_2"', 'name="spring_marker_1"')
    with pytest.raises(InputError, match="spring 'spring_marker_1' appears twice") as info:
        parse_osimx(text)
    assert info.value.line == _line(text, '<GCPSpring name="spring_marker_1"', 2)


def test_a_muscle_group_twice_is_an_error_at_the_second() -> None:
    text = _text(synergies=(OsimxSynergy("RightLeg", 5), OsimxSynergy("RightLeg", 5)))
    with pytest.raises(InputError, match="muscle group 'RightLeg' has two <RCNLSynergy>") as info:
        parse_osimx(text)
    assert info.value.line == _line(text, "<RCNLSynergy>", 2)
    assert len(parse_osimx(_text(synergies=(OsimxSynergy("RightLeg", 5), OsimxSynergy("LeftLeg", 4)))).synergies) == 2


def test_two_surfaces_on_one_hindfoot_or_one_without_springs_are_refused_where_applied(tmp_path: Path) -> None:
    path = tmp_path / "twice.osimx"
    path.write_text(_text(_surface("calcn_r"), _surface("calcn_r")))
    twice = read_osimx(path)  # read (GCP replaces the surfaces of the feet it personalizes) ...
    with pytest.raises(InputError, match="two contact surfaces on 'calcn_r' \\(also at line") as info:
        check_contact_surfaces(twice)  # ... refused where applied as contact
    assert info.value.file == str(path) and info.value.line == _line(path.read_text(), "<RCNLContactSurface>", 2)
    setup = SimpleNamespace(osimx=path, model=SimpleNamespace(model=object()))
    with pytest.raises(InputError, match="two contact surfaces"):
        ElasticFoundationContact.discover(setup)  # the treatment tools' foot contact
    path.write_text(_text(_surface("calcn_r"), _surface("calcn_l", springs=0)))
    with pytest.raises(InputError, match="the contact surface on 'calcn_l' has no springs") as info:
        ElasticFoundationContact.discover(setup)
    assert info.value.line == _line(path.read_text(), "<RCNLContactSurface>", 2)
    check_contact_surfaces(parse_osimx(_text(_surface("calcn_r"), _surface("calcn_l"))))  # two feet


@pytest.mark.shared_data
def test_export_refuses_a_copied_contact_surface_and_writes_nothing(shared_data: Path, tmp_path: Path, capsys) -> None:
    folder = shared_data / "gcp" / "uf_subject3_tutorial"
    text = (folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").read_text(encoding="utf-8")
    text = re.sub(r"<resting_spring_length>[^<]*<", "<resting_spring_length>0.01<", text)
    surface = re.search(r"<RCNLContactSurface>.*</RCNLContactSurface>", text, re.S).group(0)
    osimx = tmp_path / "copied_surface.osimx"
    osimx.write_text(text.replace(surface, surface + surface), encoding="utf-8")
    output = tmp_path / "exported.osim"
    args = ["export", str(osimx), "--model", str(folder / "bodyModel.osim")]
    assert main([*args, "-o", str(output)]) != 0
    err = capsys.readouterr().err
    assert "two contact surfaces on 'calcn_r'" in err and "Traceback" not in err
    assert not output.exists()
    assert main([*args, "--no-contact", "-o", str(output)]) == 0

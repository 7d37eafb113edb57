""".osimx files: every shared file, round trips, unknown elements, old layouts."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.osimx import (
    GcpSpring,
    OsimxContactSurface,
    OsimxModel,
    OsimxMuscle,
    OsimxSynergy,
    check_muscles_in_model,
    format_osimx,
    parse_osimx,
    read_osimx,
    write_osimx,
)

#: shared files in the old ground-contact layout (toe coordinate instead of hindfoot body)
OLD_CONTACT_LAYOUT = {
    "core/nmsm_core_tests/osimx/full_model.osimx",
    "core/nmsm_core_tests/osimx/full_model2.osimx",
    "gcp/patient3_right_foot/optModel_v6_correct_height_groundContactModel.osimx",
}
_SET_ALIASES = {"MTPMuscleSet": "RCNLMuscleSet", "OpenSimDocument": "NMSMPipelineDocument"}


def _leaves(path: Path) -> list[tuple[str, object]]:
    """(element path, value) of every leaf, with set wrappers and old names normalized."""
    root = etree.parse(str(path), etree.XMLParser(remove_comments=True, remove_blank_text=True)).getroot()
    out = []
    for element in root.iter():
        if len(element) or element.tag in ("groups", "objects"):
            continue
        parts = [_SET_ALIASES.get(a.tag, a.tag) for a in reversed(list(element.iterancestors())) if a.tag != "objects"]
        name = element.get("name")
        key = "/".join(parts + [element.tag + (f"[{name}]" if name else "")])
        text = (element.text or "").strip()
        try:
            value: object = tuple(float(v) for v in text.split()) if text else ""
        except ValueError:
            value = text
        out.append((key, value))
    return sorted(out, key=lambda kv: kv[0])


@pytest.mark.shared_data
def test_every_shared_osimx_reads_and_round_trips(shared_data: Path, tmp_path: Path) -> None:
    files = sorted(shared_data.rglob("*.osimx"))
    assert len(files) == 20
    read = 0
    for path in files:
        relative = path.relative_to(shared_data).as_posix()
        if relative in OLD_CONTACT_LAYOUT:
            with pytest.raises(InputError, match="old ground-contact layout"):
                read_osimx(path)
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # OpenSimDocument roots, MTPMuscleSet and their scale factors warn
            model = read_osimx(path)
            copy = write_osimx(tmp_path / "copy.osimx", model)
            assert read_osimx(copy) == model, relative
        assert _leaves(copy) == _leaves(path), relative  # every element and value kept
        read += 1
    assert read == 17


@pytest.mark.shared_data
def test_shared_values(shared_data: Path) -> None:
    mtp = read_osimx(shared_data / "ncp/uf_subject3_tutorial/mtpResults/UF_Subject_3_reduced_muscles_mtp.osimx")
    assert len(mtp.muscles) == 9 and mtp.name == "UF_Subject_3_reduced_muscles" and mtp.version == "0.1.0"
    bflh = mtp.muscles["bflh_r"]
    assert bflh.electromechanical_delay == 1.30153048225587e-19 and bflh.max_isometric_force == 2794.97165154896
    gcp = read_osimx(shared_data / "gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPResultsV1/bodyModel_gcp.osimx")
    (surface,) = gcp.contact_surfaces
    assert surface.hindfoot_body == "calcn_r" and not surface.is_left_foot and surface.belt_speed == 1.4
    assert surface.force_columns == ("ground_force_2_vx", "ground_force_2_vy", "ground_force_2_vz")
    assert len(surface.springs) == 37 and surface.springs[0].name == "spring_marker_1"
    assert surface.springs[0].location == (0.157362911100378, -0.0372248687699037, -0.0468935233609693)
    ncp = read_osimx(shared_data / "treatment/synergy_kick_tutorial/ncpResults/KickingModel_ncp.osimx")
    assert ncp.synergies[0].num_synergies > 0 and ncp.muscles["soleus_r"].emg_scale_factor is None
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        old = read_osimx(shared_data / "ncp/patient3_bilateral_trials1to3/mtpResults/model.osimx")
    messages = [str(w.message) for w in record]
    assert any("<OpenSimDocument>" in m for m in messages) and any("<MTPMuscleSet>" in m for m in messages)
    assert len(old.muscles) == 90 and "optimal_fiber_length_scale_factor" in old.muscles["addbrev_r"].extra[0]


def _model() -> OsimxModel:
    spring = GcpSpring(
        name="spring_marker_1", parent_body="calcn_r", location=(0.1 / 3, -0.02, 1e-17), spring_constant=4100.0
    )
    surface = OsimxContactSurface(
        is_left_foot=True,
        belt_speed=0.0,
        force_columns=("fx", "fy", "fz"),
        moment_columns=("mx", "my", "mz"),
        electrical_center_columns=("px", "py", "pz"),
        hindfoot_body="calcn_l",
        toe_marker="T",
        medial_marker="M",
        lateral_marker="L",
        heel_marker="H",
        midfoot_superior_marker="S",
        resting_spring_length=0.021,
        dynamic_friction_coefficient=0.6,
        viscous_friction_coefficient=0.0,
        damping_factor=0.3,
        latching_velocity=0.05,
        springs=(spring,),
    )
    muscles = {
        "soleus_r": OsimxMuscle(name="soleus_r", electromechanical_delay=0.45, tendon_slack_length=0.262),
        "tibant_r": OsimxMuscle(name="tibant_r", max_isometric_force=905.0),
    }
    return OsimxModel(
        name="subject",
        associated_osim_model="subject.osim",
        muscles=muscles,
        contact_surfaces=(surface,),
        synergies=(OsimxSynergy("RightLeg", 5),),
    )


def test_round_trip_with_fifteen_significant_digits(tmp_path: Path) -> None:
    model = _model()
    text = format_osimx(model)
    assert "<location>0.0333333333333333 -0.02 1e-17</location>" in text
    assert '<NMSMPipelineDocument Version="1.5.3">' in text
    again = read_osimx(write_osimx(tmp_path / "m.osimx", model))
    assert again.contact_surfaces[0].springs[0].location[0] == float("%.15g" % (0.1 / 3))
    assert again.muscles == model.muscles and again.synergies == model.synergies
    assert again.muscles["tibant_r"].optimal_fiber_length is None  # absent stays absent
    assert read_osimx(write_osimx(tmp_path / "n.osimx", again)) == again


def test_unknown_elements_are_kept_where_they_were(tmp_path: Path) -> None:
    text = (
        format_osimx(_model())
        .replace(
            "<tendon_slack_length>0.262</tendon_slack_length>",
            "<tendon_slack_length>0.262</tendon_slack_length><future_field unit='s'>3</future_field>",
        )
        .replace("</OsimxModel>", "<RCNLJointSet><joint name='knee'>1</joint></RCNLJointSet></OsimxModel>")
    )
    with pytest.warns(UserWarning, match="unknown element") as record:
        model = parse_osimx(text)
    assert len(record) == 2
    assert model.muscles["soleus_r"].extra == ('<future_field unit="s">3</future_field>',)
    assert "RCNLJointSet" in model.extra[0]
    path = write_osimx(tmp_path / "k.osimx", model)
    with pytest.warns(UserWarning, match="unknown element"):
        again = read_osimx(path)
    assert again == model
    root = etree.parse(str(path)).getroot()
    assert root.find(".//RCNLMuscle[@name='soleus_r']/future_field").text == "3"
    assert root.find("OsimxModel/RCNLJointSet/joint").get("name") == "knee"


def test_old_toes_coordinate_is_an_error() -> None:
    text = format_osimx(_model()).replace(
        "<hindfoot_body>calcn_l</hindfoot_body>", "<toes_coordinate>mtp_angle_l</toes_coordinate>"
    )
    with pytest.raises(InputError) as info:
        parse_osimx(text)
    assert info.value.element == "<toes_coordinate>" and info.value.line is not None


def test_bad_osimx_input(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="lacks <damping_factor>"):
        parse_osimx(format_osimx(_model()).replace("<damping_factor>0.3</damping_factor>", ""))
    with pytest.raises(InputError, match="associated_osim_model"):
        parse_osimx("<NMSMPipelineDocument Version='1.5.3'><OsimxModel name='m'/></NMSMPipelineDocument>")
    with pytest.raises(InputError, match="'abc' is not a number"):
        parse_osimx(format_osimx(_model()).replace("<electromechanical_delay>0.45", "<electromechanical_delay>abc"))
    with pytest.raises(InputError, match="appears twice"):
        parse_osimx(format_osimx(_model()).replace('name="tibant_r"', 'name="soleus_r"'))
    with pytest.raises(InputError) as info:
        parse_osimx("<NMSMPipelineDocument>\n<OsimxModel>\n</NMSMPipelineDocument>")
    assert info.value.line == 3 and "malformed XML" in info.value.detail
    with pytest.raises(InputError, match="root element"):
        parse_osimx("<Model/>")
    with pytest.raises(InputError, match="cannot read"):
        read_osimx(tmp_path / "missing.osimx")


def test_model_path_resolves_relative_to_the_osimx_file(tmp_path: Path) -> None:
    (tmp_path / "subject.osim").write_text("<OpenSimDocument/>")
    path = write_osimx(tmp_path / "s.osimx", _model())
    assert read_osimx(path).model_path(path) == (tmp_path / "subject.osim").resolve()


# ----- warnings for unknown elements ------------------------------------------------------
def _read_recording(path: Path) -> tuple[OsimxModel, list[str]]:
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        model = read_osimx(path)
    return model, [str(w.message) for w in record if issubclass(w.category, UserWarning)]


def _line_of(path: Path, text: str) -> int:
    return next(i for i, line in enumerate(path.read_text().splitlines(), start=1) if text in line)


def test_misspelled_field_warns_with_file_line_parent_and_close_match(tmp_path: Path) -> None:
    text = format_osimx(_model()).replace("tendon_slack_length>", "tendon_slack_lenght>")
    path = tmp_path / "typo.osimx"
    path.write_text(text)
    model, messages = _read_recording(path)
    (message,) = messages
    line = _line_of(path, "<tendon_slack_lenght>")
    assert message.startswith(f"{path}:{line}: unknown element <tendon_slack_lenght>")
    assert '<RCNLMuscle name="soleus_r">' in message and "did you mean <tendon_slack_length>?" in message
    assert model.muscles["soleus_r"].tendon_slack_length is None  # not used ...
    assert "tendon_slack_lenght" in model.muscles["soleus_r"].extra[0]  # ... but kept
    again, _ = _read_recording(write_osimx(tmp_path / "again.osimx", model))
    assert again == model  # and written back


def test_misspelled_muscle_set_warns_and_is_kept(tmp_path: Path) -> None:
    path = tmp_path / "set.osimx"
    path.write_text(format_osimx(_model()).replace("RCNLMuscleSet>", "RCNLMusclesSet>"))
    model, messages = _read_recording(path)
    (message,) = messages
    assert f"{path}:{_line_of(path, '<RCNLMusclesSet>')}: unknown element <RCNLMusclesSet>" in message
    assert '<OsimxModel name="subject">' in message and "did you mean <RCNLMuscleSet>?" in message
    assert not model.muscles and "RCNLMusclesSet" in model.extra[0]


def test_unknown_set_member_warns_and_is_dropped(tmp_path: Path) -> None:
    path = tmp_path / "m.osimx"
    path.write_text(format_osimx(_model()).replace("RCNLSynergy>", "RCNLSynergyy>"))
    model, messages = _read_recording(path)
    (message,) = messages
    assert f"{path}:{_line_of(path, '<RCNLSynergyy>')}: unknown element <RCNLSynergyy> in <RCNLSynergySet>" in message
    assert "ignored and not written back (did you mean <RCNLSynergy>?)" in message
    assert not model.synergies


def test_unknown_spring_child_warns(tmp_path: Path) -> None:
    path = tmp_path / "s.osimx"
    path.write_text(format_osimx(_model()).replace("<parent_body>", "<stiffness>1</stiffness><parent_body>"))
    model, messages = _read_recording(path)
    (message,) = messages
    assert '<stiffness> in <GCPSpring name="spring_marker_1">: kept and written back' in message
    assert "known here: <parent_body>, <location>, <spring_constant>" in message
    assert model.contact_surfaces[0].springs[0].extra == ("<stiffness>1</stiffness>",)


def test_text_without_a_file_names_the_text() -> None:
    with pytest.warns(UserWarning, match=r"^\(\.osimx text\):\d+: unknown element <future>"):
        parse_osimx(format_osimx(_model()).replace("</OsimxModel>", "<future/></OsimxModel>"))


def test_written_osimx_reads_without_warnings(tmp_path: Path) -> None:
    path = write_osimx(tmp_path / "m.osimx", _model())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert format_osimx(read_osimx(path)) == format_osimx(_model())


@pytest.mark.shared_data
def test_shared_osimx_files_warn_only_about_old_layouts(shared_data: Path) -> None:
    """Current files read silently; 2023 files get their two layout warnings, no "unknown element"."""
    silent = 0
    for path in sorted(shared_data.rglob("*.osimx")):
        if path.relative_to(shared_data).as_posix() in OLD_CONTACT_LAYOUT:
            continue
        _, messages = _read_recording(path)
        if etree.parse(str(path)).getroot().tag == "NMSMPipelineDocument":
            assert messages == [], path
            silent += 1
        else:
            assert len(messages) == 2 and "<OpenSimDocument>" in messages[0] and "<MTPMuscleSet>" in messages[1], path
    assert silent == 15


def test_old_scale_factors_outside_mtp_muscle_set_warn_once(tmp_path: Path) -> None:
    factor = "<optimal_fiber_length_scale_factor>1.1</optimal_fiber_length_scale_factor>"
    path = tmp_path / "old.osimx"
    path.write_text(format_osimx(_model()).replace("</RCNLMuscle>", factor + "</RCNLMuscle>"))
    model, messages = _read_recording(path)
    (message,) = messages
    assert "2 2023 length scale factor(s)" in message and "unknown element" not in message
    assert all("scale_factor" in m.extra[-1] for m in model.muscles.values())
    path.write_text(path.read_text().replace("RCNLMuscleSet", "MTPMuscleSet"))
    _, messages = _read_recording(path)
    (message,) = messages  # the <MTPMuscleSet> warning covers its scale factors
    assert "old <MTPMuscleSet>" in message


# ----- muscles applied to a model ---------------------------------------------------------
def test_muscle_not_in_model_is_an_error_naming_file_line_and_close_matches(tmp_path: Path) -> None:
    path = tmp_path / "m.osimx"
    path.write_text(format_osimx(_model()).replace('name="tibant_r"', 'name="tib_ant_r"'))
    osimx = read_osimx(path)
    check_muscles_in_model(osimx, ["soleus_r", "tib_ant_r", "gasmed_r"])  # a subset of the model is fine
    with pytest.raises(InputError) as info:
        check_muscles_in_model(osimx, ["soleus_r", "tibant_r", "gasmed_r"], model_file="subject.osim")
    error = info.value
    assert error.file == str(path) and error.line == _line_of(path, 'name="tib_ant_r"')
    assert error.element == '<RCNLMuscle name="tib_ant_r">'
    assert "muscle 'tib_ant_r' is not in the model subject.osim; did you mean 'tibant_r'?" in str(error)
    assert "muscles of the model: soleus_r, tibant_r, gasmed_r" in str(error)


def test_every_muscle_not_in_model_is_named() -> None:
    osimx = _model()  # built in code: no file, no line
    with pytest.raises(InputError) as info:
        check_muscles_in_model(osimx, ["vasmed_r"], osimx_file="given.osimx")
    assert info.value.file == "given.osimx" and info.value.line is None
    message = str(info.value)
    assert "muscle 'soleus_r' is not in the model" in message and "also not in the model: tibant_r" in message


@pytest.mark.shared_data
def test_treatment_muscle_model_rejects_an_osimx_muscle_not_in_the_model(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.controllers.muscle import PathGeometry
    from nmsm.examples.moco2d import MUSCLE_COORDINATES
    from nmsm.model import load_model
    from nmsm.model.muscle_model import MuscleModel

    model = load_model(shared_data / "moco2d" / "2D_gait.osim")
    names = [m.name for m in model.muscles]
    geometry = PathGeometry(model, MUSCLE_COORDINATES)
    good = OsimxModel("m", "2D_gait.osim", {names[0]: OsimxMuscle(names[0], max_isometric_force=1234.0)})
    built = MuscleModel.build(names, MUSCLE_COORDINATES, geometry, model, good, 10.0)
    assert built.parameters[names[0]]["max_isometric_force"] == 1234.0
    typo = names[0] + "x"
    path = write_osimx(tmp_path / "bad.osimx", OsimxModel("m", "2D_gait.osim", {typo: OsimxMuscle(typo)}))
    with pytest.raises(InputError) as info:
        MuscleModel.build(names, MUSCLE_COORDINATES, geometry, model, read_osimx(path), 10.0)
    assert str(path) in str(info.value) and f"did you mean '{names[0]}'" in str(info.value)

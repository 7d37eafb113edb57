""".osimx numbers that no tool can use (fuzz audit of .osimx files).

``float()`` read ``nan``, ``inf`` and ``1e400``, and nothing checked a sign: ``nmsm export``
wrote ``<optimal_fiber_length>nan</optimal_fiber_length>``, ``<activation_time_constant>Inf``
or a negative tendon slack length into the exported ``.osim`` and exited 0. Now every number
of an ``.osimx`` is finite, and the fields whose sign is physical are checked where the file
is read, one error naming the file, the line, the element and what was expected. What the
original tools write stays accepted: a negative resting spring length (GCP leaves it free),
a zero maximum isometric force (the original's own test files), a negative belt speed and a
round-off negative electromechanical delay (the original's Patient 3 MTP file: -2.7e-40; NCP
copied an input's nan or -1 delay into its output .osimx).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.osimx import GcpSpring, OsimxContactSurface, OsimxModel, OsimxMuscle, format_osimx, parse_osimx


def _text() -> str:
    spring = GcpSpring(name="spring_marker_1", parent_body="calcn_r", location=(0.01, -0.02, 0.03),
                       spring_constant=4100.0)
    surface = OsimxContactSurface(
        is_left_foot=False, belt_speed=1.2, force_columns=("fx", "fy", "fz"), moment_columns=("mx", "my", "mz"),
        electrical_center_columns=("px", "py", "pz"), hindfoot_body="calcn_r", toe_marker="T", medial_marker="M",
        lateral_marker="L", heel_marker="H", midfoot_superior_marker="S", resting_spring_length=0.021,
        dynamic_friction_coefficient=0.6, viscous_friction_coefficient=0.1, damping_factor=0.3,
        latching_velocity=0.05, springs=(spring,),
    )
    muscle = OsimxMuscle(name="soleus_r", electromechanical_delay=0.45, activation_time_constant=1.2,
                         activation_nonlinearity_constant=0.08, emg_scale_factor=0.41, optimal_fiber_length=0.047,
                         tendon_slack_length=0.262, max_isometric_force=6100.0)
    return format_osimx(OsimxModel(name="subject", associated_osim_model="subject.osim",
                                   muscles={"soleus_r": muscle}, contact_surfaces=(surface,)))


def _with(tag: str, value: str) -> str:
    text, count = re.subn(f"<{tag}>[^<]*</{tag}>", f"<{tag}>{value}</{tag}>", _text())
    assert count == 1, tag
    return text


def _line_of(text: str, tag: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), start=1) if f"<{tag}>" in line)


NUMBERS = ("electromechanical_delay", "activation_time_constant", "activation_nonlinearity_constant",
           "emg_scale_factor", "optimal_fiber_length", "tendon_slack_length", "max_isometric_force", "belt_speed",
           "resting_spring_length", "dynamic_friction_coefficient", "viscous_friction_coefficient",
           "damping_factor", "latching_velocity", "spring_constant")


@pytest.mark.parametrize("value", ["nan", "NaN", "inf", "-Inf", "1e400"])
@pytest.mark.parametrize("tag", NUMBERS)
def test_a_number_that_is_not_finite_is_one_error_at_its_line(tag: str, value: str, tmp_path: Path) -> None:
    text = _with(tag, value)
    path = tmp_path / "subject.osimx"
    with pytest.raises(InputError) as info:
        parse_osimx(text, source=path)
    assert info.value.line == _line_of(text, tag)
    assert info.value.element == f"<{tag}>" and info.value.file == str(path)
    assert "finite" in str(info.value)


@pytest.mark.parametrize("location", ["0.1 0.2 nan", "inf 0 0"])
def test_a_spring_location_that_is_not_finite_is_an_error(location: str) -> None:
    with pytest.raises(InputError, match="three finite numbers") as info:
        parse_osimx(_with("location", location))
    assert info.value.element == "<location>"


@pytest.mark.parametrize(("tag", "value", "expected"), [
    ("optimal_fiber_length", "0", "> 0"), ("optimal_fiber_length", "-0.05", "> 0"),
    ("tendon_slack_length", "0", "> 0"), ("tendon_slack_length", "-1", "> 0"),
    ("activation_time_constant", "0", "> 0"), ("emg_scale_factor", "-0.4", "> 0"),
    ("latching_velocity", "0", "> 0"), ("max_isometric_force", "-6100", ">= 0"),
    ("electromechanical_delay", "-1", ">= 0"), ("electromechanical_delay", "-0.01", ">= 0"),
    ("spring_constant", "-4100", ">= 0"), ("damping_factor", "-0.3", ">= 0"),
    ("dynamic_friction_coefficient", "-0.6", ">= 0"), ("viscous_friction_coefficient", "-1", ">= 0"),
])
def test_a_value_of_the_wrong_sign_is_one_error_naming_the_limit(tag: str, value: str, expected: str) -> None:
    text = _with(tag, value)
    with pytest.raises(InputError) as info:
        parse_osimx(text)
    assert info.value.line == _line_of(text, tag) and info.value.element == f"<{tag}>"
    assert f"expected a number {expected}" in str(info.value)


@pytest.mark.parametrize(("tag", "value"), [
    ("resting_spring_length", "-0.0004312"), ("belt_speed", "-1.2"), ("max_isometric_force", "0"),
    ("electromechanical_delay", "-2.6632e-40"), ("activation_nonlinearity_constant", "0"),
    ("spring_constant", "0"), ("viscous_friction_coefficient", "0"),
])
def test_values_the_original_writes_are_accepted(tag: str, value: str) -> None:
    model = parse_osimx(_with(tag, value))
    surface = model.contact_surfaces[0]
    owner = next(o for o in (surface, surface.springs[0], model.muscles["soleus_r"]) if hasattr(o, tag))
    assert getattr(owner, tag) == float(value)


@pytest.mark.shared_data
@pytest.mark.parametrize("value", ["nan", "0"])
def test_export_refuses_the_value_and_writes_nothing(shared_data: Path, tmp_path: Path, capsys, value: str) -> None:
    folder = shared_data / "mtp" / "uf_subject3_tutorial"
    source = folder / "CompletedSettingsFiles" / "MTPResultsV1" / "UF_Subject_3_reduced_muscles_mtp.osimx"
    text = source.read_text(encoding="utf-8")
    text, count = re.subn(r"<optimal_fiber_length>[^<]*<", f"<optimal_fiber_length>{value}<", text, count=1)
    assert count == 1
    osimx = tmp_path / "mutated.osimx"
    osimx.write_text(text, encoding="utf-8")
    output = tmp_path / "exported.osim"
    code = main(["export", str(osimx), "--model", str(folder / "UF_Subject_3_reduced_muscles.osim"), "-o", str(output)])
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err
    assert f"{osimx}:{_line_of(text, 'optimal_fiber_length')}: <optimal_fiber_length>" in err
    assert not output.exists()

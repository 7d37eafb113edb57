"""Inputs that used to be accepted although wrong are refused with the project's error,
naming the file: an ``inDegrees`` value other than yes/no, a motion without rows, a motion
whose inverse dynamics overflow, negative mass, non-finite inertia, a reversed coordinate
range and a component name with '/'."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from nmsm.errors import InputError, ModelError

TOY = "jmp/toy_simple_arm"


def _motion(path: Path, header: str = "inDegrees=yes", rows: str = "") -> Path:
    path.write_text(f"simple_arm.mot\nversion=1\nnColumns=2\n{header}\nendheader\ntime\tr_elbow_flex\n{rows}",
                    encoding="utf-8")
    return path


@pytest.mark.parametrize("value", ["true", "True", "1", "degrees", ""])
def test_in_degrees_other_than_yes_or_no_is_refused(tmp_path: Path, value: str) -> None:
    """OpenSim 4.6 (Storage.isInDegrees) reads only 'yes' (any case) as degrees: 'true' would
    be radians there, degrees to the user who wrote it."""
    from nmsm.io.storage import read_storage

    path = _motion(tmp_path / "m.mot", f"inDegrees={value}", "0\t10\n0.1\t20\n")
    with pytest.raises(InputError) as caught:
        read_storage(path)
    message = str(caught.value)
    assert f"{path}:4: inDegrees:" in message and "inDegrees=yes" in message


@pytest.mark.parametrize("value, degrees", [("yes", True), ("YES", True), ("no", False), ("No", False)])
def test_in_degrees_yes_or_no_in_any_case(tmp_path: Path, value: str, degrees: bool) -> None:
    from nmsm.io.storage import read_storage

    path = _motion(tmp_path / "m.mot", f"inDegrees={value}", "0\t10\n0.1\t20\n")
    assert read_storage(path).in_degrees is degrees


@pytest.mark.parametrize("command", ["markers", "id"])
def test_a_motion_without_rows_is_refused(shared_data: Path, tmp_path: Path, command: str,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    from nmsm.cli import main

    motion = _motion(tmp_path / "empty.mot")
    out = tmp_path / ("out.trc" if command == "markers" else "out.sto")
    assert main([command, str(shared_data / TOY / "simple_arm.osim"), str(motion), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"nmsm: error: {motion}: ") and "no rows" in err
    assert not out.exists()


def test_inverse_dynamics_that_overflow_are_refused(shared_data: Path, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    from nmsm.cli import main

    rows = "".join(f"{0.01 * k:g}\t{1e300 * (k % 2) - 1e299:g}\n" for k in range(10))
    motion = _motion(tmp_path / "huge.mot", "inDegrees=no", rows)
    out = tmp_path / "id.sto"
    assert main(["id", str(shared_data / TOY / "simple_arm.osim"), str(motion), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{motion}" in err and "not finite" in err and "r_elbow_flex" in err
    assert not out.exists()


@pytest.mark.parametrize("old, new, words", [
    ("<mass>1.8645719999999999</mass>", "<mass>-1.86</mass>", "negative mass"),
    ("<inertia>0.01481 ", "<inertia>nan ", "<inertia> is not finite"),
    ("<mass>1.8645719999999999</mass>", "<mass>inf</mass>", "<mass> is not finite"),
    ("<range>0 2.2689280300000001</range>", "<range>2.26 0</range>", "is not a range"),
    ('<Coordinate name="r_elbow_flex">', '<Coordinate name="r_elbow/flex">', "OpenSim forbids"),
])
def test_impossible_models_are_refused(shared_data: Path, tmp_path: Path, old: str, new: str, words: str) -> None:
    from nmsm.model import load_model

    text = (shared_data / TOY / "simple_arm.osim").read_text(encoding="utf-8")
    assert old in text
    path = tmp_path / "arm.osim"
    path.write_text(text.replace(old, new, 1), encoding="utf-8")
    with pytest.raises(ModelError) as caught:
        load_model(path)
    assert str(caught.value).startswith(f"{path}:") and words in str(caught.value)


def test_the_toy_model_itself_loads(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.model import load_model

    shutil.copy(shared_data / TOY / "simple_arm.osim", tmp_path / "arm.osim")
    assert "r_elbow_flex" in load_model(tmp_path / "arm.osim").coordinate_names


def test_a_negative_max_allowable_error_is_refused_also_where_unused(shared_data: Path, tmp_path: Path) -> None:
    """NCP V1's first term (MTLI's, a block that is not enabled) was read with -2 and the run went on."""
    from nmsm.io.settings import read_tool_settings

    source = shared_data / "ncp/uf_subject3_tutorial/CompletedSettingsFiles/NCPSettingsV1.xml"
    text = source.read_text(encoding="utf-8")
    first = text.index("<max_allowable_error>")
    end = text.index("</max_allowable_error>", first)
    line = text[:first].count("\n") + 1
    path = tmp_path / "NCPSettingsV1.xml"
    path.write_text(text[:first] + "<max_allowable_error>-2" + text[end:], encoding="utf-8")
    with pytest.raises(InputError) as caught:
        read_tool_settings(path, check_paths=False)
    assert str(caught.value).startswith(f"{path}:{line}: <max_allowable_error>: ") and "> 0" in str(caught.value)

"""Paths in settings files written on Windows: back-slashes, mixed separators, absolute
Windows paths on Linux and macOS (the rule: docs/install.md, "Files from Windows")."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io import paths
from nmsm.io.paths import resolve_path


# ----- paths in settings files --------------------------------------------------------------
@pytest.fixture
def settings(tmp_path: Path) -> Path:
    (tmp_path / "step" / "data" / "preprocessed").mkdir(parents=True)
    (tmp_path / "step" / "model.osim").write_text("<m/>", encoding="utf-8")
    (tmp_path / "step" / "settings").mkdir()
    path = tmp_path / "step" / "settings" / "run.xml"
    path.write_text("<x/>", encoding="utf-8")
    return path


@pytest.mark.parametrize("text", ["..\\model.osim", "../model.osim", "..\\model.osim ", "..//model.osim"])
def test_back_slash_and_forward_slash_are_one_separator(settings: Path, text: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = resolve_path(text, settings_file=settings, element="input_model_file", kind="file")
    assert found.resolve() == (settings.parent.parent / "model.osim").resolve()


@pytest.mark.parametrize("text", ["..\\data\\preprocessed\\", "../data\\preprocessed", "..\\data/preprocessed/"])
def test_mixed_separators_in_a_folder(settings: Path, text: str) -> None:
    found = resolve_path(text, settings_file=settings, element="data_directory", kind="dir")
    assert found.resolve() == (settings.parent.parent / "data" / "preprocessed").resolve()


def test_results_folder_with_back_slashes_is_nested_not_one_name(settings: Path) -> None:
    found = resolve_path("out\\V3", settings_file=settings, element="results_directory", must_exist=False)
    assert found == (settings.parent / "out" / "V3").resolve()


@pytest.mark.parametrize(("text", "what"), [
    ("C:\\Users\\lab\\model.osim", "drive C:"),
    ("d:/study/preprocessed", "drive d:"),
    ("C:\\results", "drive C:"),
    ("\\\\labserver\\share\\model.osim", "network share"),
])
@pytest.mark.parametrize("output", [False, True])
def test_absolute_windows_path_on_linux_names_the_element(settings: Path, monkeypatch, text: str, what: str,
                                                          output: bool) -> None:
    monkeypatch.setattr(paths, "ON_WINDOWS", False)
    with pytest.raises(InputError) as info:
        resolve_path(text, settings_file=settings, line=6, element="input_model_file", must_exist=not output)
    error = info.value
    assert error.file == str(settings) and error.line == 6 and error.element == "<input_model_file>"
    assert f"absolute Windows path ({what})" in error.detail and "relative to the settings file" in error.expected
    assert not list(settings.parent.glob("*:*"))  # no folder named 'C:' made


def test_absolute_windows_path_is_left_to_windows(settings: Path, monkeypatch) -> None:
    monkeypatch.setattr(paths, "ON_WINDOWS", True)
    with pytest.raises(InputError) as info:  # not found here, but not refused as a Windows path
        resolve_path("C:\\Users\\lab\\model.osim", settings_file=settings, element="input_model_file")
    assert "absolute Windows path" not in str(info.value)


def test_absolute_windows_path_in_a_settings_file_is_refused_by_run(arm: Path, tmp_path: Path, capsys) -> None:
    text = (arm / "ToySettingsFile.xml").read_text(encoding="utf-8")
    text = text.replace("<input_model_file>simple_arm", "<input_model_file>C:\\Users\\lab\\simple_arm")
    (arm / "abs.xml").write_text(text, encoding="utf-8")
    assert main(["run", str(arm / "abs.xml"), "-o", str(tmp_path / "out")]) != 0
    err = capsys.readouterr().err
    line = 1 + text[: text.index("C:\\Users")].count("\n")
    assert f"abs.xml:{line}: <input_model_file>: 'C:\\Users\\lab\\simple_arm_translated_away.osim' is an absolute " \
           "Windows path (drive C:)" in err
    assert not (tmp_path / "out").exists()

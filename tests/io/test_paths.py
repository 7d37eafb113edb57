"""Paths written in settings files: separators, case, fallback folders, missing files."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.paths import normalize_separators, resolve_path


@pytest.fixture
def layout(tmp_path: Path) -> Path:
    """step/ with data files, step/settings/ with the settings file (the tutorial layout)."""
    (tmp_path / "settings").mkdir()
    (tmp_path / "settings" / "run.xml").write_text("<x/>")
    (tmp_path / "settings" / "model.osim").write_text("<m/>")
    (tmp_path / "MarkerFiles").mkdir()
    (tmp_path / "MarkerFiles" / "Knee.trc").write_text("t")
    (tmp_path / "preprocessed" / "IKData").mkdir(parents=True)
    return tmp_path


def test_backslash_path_is_normalized(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    (layout / "settings" / "sub").mkdir()
    (layout / "settings" / "sub" / "a.sto").write_text("x")
    assert normalize_separators(" sub\\a.sto ") == "sub/a.sto"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = resolve_path("sub\\a.sto", settings_file=settings, element="input_motion_file")
    assert found == (layout / "settings" / "sub" / "a.sto").resolve()


def test_relative_to_the_settings_folder_first(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    (layout / "model.osim").write_text("<other/>")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert resolve_path("model.osim", settings_file=settings) == (layout / "settings" / "model.osim").resolve()


def test_parent_folder_fallback_warns(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    with pytest.warns(UserWarning, match="parent of the settings file's folder"):
        found = resolve_path("MarkerFiles\\Knee.trc", settings_file=settings, kind="file")
    assert found == (layout / "MarkerFiles" / "Knee.trc").resolve()


def test_wrong_case_is_matched_with_a_warning_naming_both_spellings(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    with pytest.warns(UserWarning) as record:
        found = resolve_path("markerfiles/KNEE.trc", settings_file=settings, line=7, element="marker_file_name")
    assert found == (layout / "MarkerFiles" / "Knee.trc").resolve()
    messages = " ".join(str(w.message) for w in record)
    assert "markerfiles/KNEE.trc" in messages and "MarkerFiles/Knee.trc" in messages


def test_missing_file_names_settings_file_line_element_and_paths_tried(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    with pytest.raises(InputError) as info:
        resolve_path("nothere.osim", settings_file=settings, line=12, element="input_model_file", kind="file")
    error = info.value
    assert error.file == str(settings) and error.line == 12 and error.element == "<input_model_file>"
    assert str(layout / "settings" / "nothere.osim") in error.detail
    assert str(layout / "nothere.osim") in error.detail


def test_explicit_base_has_no_fallback(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    base = layout / "preprocessed"
    assert resolve_path("IKData", settings_file=settings, base=base, kind="dir") == base / "IKData"
    with pytest.raises(InputError, match="not found"):
        resolve_path("model.osim", settings_file=settings, base=base)


def test_kind_is_checked(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    with pytest.raises(InputError, match="existing folder"):
        resolve_path("model.osim", settings_file=settings, kind="dir")


def test_output_path_need_not_exist(layout: Path) -> None:
    settings = layout / "settings" / "run.xml"
    out = resolve_path("results\\run1", settings_file=settings, must_exist=False)
    assert out == (layout / "settings" / "results" / "run1").resolve()


def test_names_differing_only_in_case_are_ambiguous(layout: Path) -> None:
    folder = layout / "settings"
    (folder / "Data").mkdir()
    (folder / "DATA").mkdir()
    if len({p.name for p in folder.iterdir()} & {"Data", "DATA"}) < 2:  # case-insensitive file system
        pytest.skip("file system is case-insensitive")
    with pytest.raises(InputError, match="differ only in case"):
        resolve_path("data", settings_file=folder / "run.xml", line=3, element="data_directory")


def test_absolute_path(layout: Path) -> None:
    target = layout / "MarkerFiles" / "Knee.trc"
    assert resolve_path(str(target), settings_file=layout / "settings" / "run.xml") == target


def test_missing_path_error_states_the_folders_searched(layout: Path) -> None:
    """The expected-part of the error describes the search the resolver did (settings folder,
    its parent, the current directory), not only the settings folder; with a base, that base."""
    settings = layout / "settings" / "run.xml"
    with pytest.raises(InputError) as info:
        resolve_path("nothere.osim", settings_file=settings, kind="file")
    assert "settings file's folder, then in its parent folder and the current working directory" in str(info.value)
    base = layout / "preprocessed"
    with pytest.raises(InputError) as info:
        resolve_path("model.osim", settings_file=settings, base=base)
    assert f"relative paths are relative to {base.resolve()}" in str(info.value)
    assert "parent folder" not in str(info.value)

"""Case-insensitive path resolution in every branch of the resolver: ``..`` parts leaving the
settings file's folder, wrong case in a parent part, a file against a folder, the current working
directory, Windows separators, outputs below an existing folder spelled in another case."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.settings import MuscleTendonPersonalizationSettings, read_settings_document


def _case_sensitive(folder: Path) -> bool:
    (folder / "CaseProbe").write_text("x")
    sensitive = not (folder / "caseprobe").exists()
    (folder / "CaseProbe").unlink()
    return sensitive


@pytest.fixture
def study(tmp_path: Path) -> Path:
    """study/TrackingOptimization/to.xml beside study/Preprocessing/preprocessed/IKData/gait_1.sto."""
    if not _case_sensitive(tmp_path):
        pytest.skip("file system is case-insensitive: every spelling exists")
    (tmp_path / "TrackingOptimization").mkdir()
    (tmp_path / "TrackingOptimization" / "to.xml").write_text("<x/>")
    (tmp_path / "Preprocessing" / "preprocessed" / "IKData").mkdir(parents=True)
    (tmp_path / "Preprocessing" / "preprocessed" / "IKData" / "gait_1.sto").write_text("t")
    (tmp_path / "Models").mkdir()
    (tmp_path / "Models" / "Subject.osim").write_text("<m/>")
    return tmp_path


def _messages(record) -> str:
    return " | ".join(str(w.message) for w in record)


# ----- the tutorial layout, on the shared MTP settings ------------------------------------------
@pytest.mark.shared_data
def test_mtp_settings_naming_a_sibling_folder_in_another_case(shared_data: Path, tmp_path: Path) -> None:
    """``..\\preprocessing\\preprocessed`` for ``../Preprocessing/preprocessed``: resolved with a warning
    that spells the path as on disk (it raised ValueError while building that warning)."""
    if not _case_sensitive(tmp_path):
        pytest.skip("file system is case-insensitive")
    source = shared_data / "mtp" / "uf_subject3_tutorial"
    (tmp_path / "Preprocessing").mkdir()
    (tmp_path / "Preprocessing" / "preprocessed").symlink_to(source / "preprocessed", target_is_directory=True)
    (tmp_path / "Models").mkdir()
    (tmp_path / "Models" / "UF_Subject_3_reduced_muscles.osim").symlink_to(source / "UF_Subject_3_reduced_muscles.osim")
    (tmp_path / "MuscleTendonPersonalization").mkdir()
    (tmp_path / "MuscleTendonPersonalization" / "passive_moment_data").symlink_to(
        source / "passive_moment_data", target_is_directory=True)
    tree = etree.parse(str(source / "CompletedSettingsFiles" / "MTPSettingsV1.xml"))
    tool = tree.getroot()[0]
    tool.find("data_directory").text = "..\\preprocessing\\preprocessed"
    tool.find("input_model_file").text = "..\\models\\uf_subject_3_reduced_muscles.osim"
    settings_path = tmp_path / "MuscleTendonPersonalization" / "MTPSettings.xml"
    tree.write(str(settings_path))
    with pytest.warns(UserWarning) as record:
        settings = MuscleTendonPersonalizationSettings.from_document(read_settings_document(settings_path))
    assert settings.data_directory == tmp_path / "Preprocessing" / "preprocessed"
    assert settings.input_model_file == tmp_path / "Models" / "UF_Subject_3_reduced_muscles.osim"
    text = _messages(record)
    assert "spelled '../Preprocessing/preprocessed' on disk" in text
    assert "spelled '../Models/UF_Subject_3_reduced_muscles.osim' on disk" in text


# ----- ".." parts ---------------------------------------------------------------------------------
@pytest.mark.parametrize("text", ["..\\preprocessing\\preprocessed", "../PREPROCESSING/Preprocessed/",
                                  "..\\\\preprocessing\\.\\preprocessed",
                                  "../TrackingOptimization/../preprocessing/preprocessed"])
def test_dot_dot_then_wrong_case(study: Path, text: str) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    with pytest.warns(UserWarning, match="on disk") as record:
        found = resolve_path(text, settings_file=settings, element="initial_guess_directory", kind="dir")
    assert found == study / "Preprocessing" / "preprocessed"
    assert "'../Preprocessing/preprocessed' on disk" in _messages(record) or \
        "'../TrackingOptimization/../Preprocessing/preprocessed' on disk" in _messages(record)


def test_exact_spelling_with_dot_dot_has_no_dot_dot_in_the_result(study: Path) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = resolve_path("..\\Preprocessing\\preprocessed\\IKData\\gait_1.sto", settings_file=settings, kind="file")
    assert found == study / "Preprocessing" / "preprocessed" / "IKData" / "gait_1.sto"
    assert ".." not in found.parts


def test_dot_dot_after_a_file_names_nothing(study: Path) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    with pytest.raises(InputError, match="not found"):
        resolve_path("to.xml/../to.xml", settings_file=settings, kind="file")


# ----- wrong case in a parent part ----------------------------------------------------------------
def test_wrong_case_in_a_parent_part_only(study: Path) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    with pytest.warns(UserWarning) as record:
        found = resolve_path("../preprocessing/preprocessed/IKData/gait_1.sto", settings_file=settings, kind="file")
    assert found == study / "Preprocessing" / "preprocessed" / "IKData" / "gait_1.sto"
    assert "spelled '../Preprocessing/preprocessed/IKData/gait_1.sto' on disk" in _messages(record)


def test_parent_part_matching_two_folders_is_ambiguous(study: Path) -> None:
    (study / "PREPROCESSING").mkdir()
    with pytest.raises(InputError, match="differ only in case") as info:
        resolve_path("../preprocessing/preprocessed", settings_file=study / "TrackingOptimization" / "to.xml",
                     line=4, element="data_directory")
    assert info.value.line == 4 and info.value.element == "<data_directory>"


def test_a_parent_part_matches_folders_only(study: Path) -> None:
    """A file ``PREPROCESSING`` beside the folder ``Preprocessing`` cannot be a parent: no ambiguity."""
    (study / "PREPROCESSING").write_text("a file")
    with pytest.warns(UserWarning, match="on disk"):
        found = resolve_path("../preprocessing/preprocessed", settings_file=study / "TrackingOptimization" / "to.xml",
                             kind="dir")
    assert found == study / "Preprocessing" / "preprocessed"


# ----- a file vs a folder -------------------------------------------------------------------------
def test_last_part_matches_the_kind_asked_for(study: Path) -> None:
    """``models`` (a file) and ``Models`` (a folder): a folder is asked for, the folder is found."""
    (study / "models").write_text("a file")
    settings = study / "TrackingOptimization" / "to.xml"
    with pytest.warns(UserWarning, match="spelled '../Models' on disk"):
        assert resolve_path("../MODELS", settings_file=settings, kind="dir") == study / "Models"
    with pytest.warns(UserWarning, match="spelled '../models' on disk"):
        assert resolve_path("../MODELS", settings_file=settings, kind="file") == study / "models"


def test_a_folder_is_not_a_file(study: Path) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    with pytest.raises(InputError, match="an existing file"):
        resolve_path("../preprocessing/preprocessed/ikdata", settings_file=settings, kind="file")
    with pytest.raises(InputError, match="an existing folder"):
        resolve_path("../models/subject.OSIM", settings_file=settings, kind="dir")


# ----- the current working directory --------------------------------------------------------------
def test_no_settings_file_resolves_in_the_current_directory(study: Path, monkeypatch) -> None:
    monkeypatch.chdir(study / "TrackingOptimization")
    with pytest.warns(UserWarning, match="spelled '../Models/Subject.osim' on disk"):
        assert resolve_path("..\\models\\subject.osim", kind="file") == study / "Models" / "Subject.osim"


def test_current_directory_fallback_with_wrong_case(study: Path, monkeypatch, tmp_path_factory) -> None:
    """Found only relative to the working directory (the third place), in another case: both warnings."""
    elsewhere = tmp_path_factory.mktemp("elsewhere") / "deep" / "settings"
    elsewhere.mkdir(parents=True)
    monkeypatch.chdir(study / "TrackingOptimization")
    with pytest.warns(UserWarning) as record:
        found = resolve_path("../models/SUBJECT.osim", settings_file=elsewhere / "run.xml", kind="file")
    assert found == study / "Models" / "Subject.osim"
    text = _messages(record)
    assert "spelled '../Models/Subject.osim' on disk" in text and "current working directory" in text


# ----- outputs ------------------------------------------------------------------------------------
def test_output_below_an_existing_folder_in_another_case(study: Path) -> None:
    """A results folder that does not exist yet is created inside the existing folder, not beside it."""
    settings = study / "TrackingOptimization" / "to.xml"
    with pytest.warns(UserWarning, match="spelled '../Preprocessing/results/V1' on disk"):
        found = resolve_path("..\\preprocessing\\results\\V1", settings_file=settings, must_exist=False)
    assert found == study / "Preprocessing" / "results" / "V1"


def test_output_spelled_exactly_does_not_warn(study: Path) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found = resolve_path("../Preprocessing/new/../results", settings_file=settings, must_exist=False)
    assert found == study / "Preprocessing" / "results"


# ----- an explicit base folder (GCP's <input_directory>) ----------------------------------------
def test_explicit_base_with_dot_dot_and_wrong_case(study: Path) -> None:
    settings = study / "TrackingOptimization" / "to.xml"
    base = study / "Preprocessing" / "preprocessed"
    with pytest.warns(UserWarning, match="spelled '../../Models/Subject.osim' on disk"):
        found = resolve_path("..\\..\\models\\SUBJECT.osim", settings_file=settings, base=base, kind="file")
    assert found == study / "Models" / "Subject.osim"
    with pytest.raises(InputError, match=r"relative paths are relative to"):
        resolve_path("..\\models\\SUBJECT.osim", settings_file=settings, base=base, kind="file")


@pytest.mark.parametrize("text", ["/", ".", "..", "up/.."])
def test_a_folder_reached_by_dots_or_the_root_is_no_file(tmp_path, text):
    """A path whose last part is ``..``, ``.`` or the root names a folder: asked for a file, it
    is not found (it was returned as the file, and reading it failed without naming the
    settings file)."""
    settings = tmp_path / "pipeline" / "p.xml"
    (tmp_path / "pipeline" / "up").mkdir(parents=True)
    settings.write_text("<x/>")
    with pytest.raises(InputError, match=r"p\.xml:3: <settings_file>: .* not found"):
        resolve_path(text, settings_file=settings, line=3, element="settings_file", kind="file")
    assert resolve_path(text, settings_file=settings, line=3, element="settings_file", kind="dir").is_dir()

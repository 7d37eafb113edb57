"""A stage's input digest sees a value written after an XML comment inside its element.

Settings values leave out comments inside them (``<max_iterations><!-- c -->60</max_iterations>``
is 60: ``nmsm.io.xml_input.element_text``), but the digest removed the comments with lxml's
``remove``, which drops the comment's tail, i.e. the value: editing such a value left the
digest unchanged, so ``nmsm pipeline`` would skip the stage and keep results of the old value."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.io.settings.mtp import MuscleTendonPersonalizationSettings
from nmsm.tools.pipeline.hashing import DigestCache
from nmsm.tools.pipeline.stage_settings import StageSettings


def _digest(shared_data: Path, tmp_path: Path, old: str, new: str) -> str:
    tutorial = shared_data / "mtp" / "uf_subject3_tutorial" / "CompletedSettingsFiles"
    text = (tutorial / "MTPSettingsV3.xml").read_text()
    assert old in text
    path = tmp_path / "CompletedSettingsFiles" / "MTPSettings.xml"
    path.parent.mkdir(exist_ok=True)
    path.write_text(text.replace(old, new, 1))
    (tmp_path / "preprocessed").mkdir(exist_ok=True)
    settings = StageSettings.from_file(path, MuscleTendonPersonalizationSettings)
    return settings.input_digest(DigestCache(), "MTP")


@pytest.mark.shared_data
def test_a_value_after_a_comment_changes_the_digest(shared_data: Path, tmp_path: Path) -> None:
    old = "<max_iterations>1000</max_iterations>"
    first = _digest(shared_data, tmp_path, old, "<max_iterations><!-- was 1000 -->50</max_iterations>")
    second = _digest(shared_data, tmp_path, old, "<max_iterations><!-- was 1000 -->60</max_iterations>")
    same = _digest(shared_data, tmp_path, old, "<max_iterations>50<!-- was 1000 --></max_iterations>")
    assert first != second
    assert first == same  # the comment itself is not part of the digest


@pytest.mark.shared_data
def test_a_path_after_a_comment_is_written_and_digested_as_the_path(shared_data: Path, tmp_path: Path) -> None:
    """A path value written after a comment (``<input_model_file><!-- c -->../m.osim``) is made
    relative to the written stage file like any other, with nothing of the old text left
    behind (it was skipped, absolute paths stayed, and the copy read them from its own folder)."""
    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    text = (tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml").read_text()
    model = tmp_path / "results" / "models" / "model.osim"
    model.parent.mkdir(parents=True)
    model.write_bytes((tutorial / "UF_Subject_3_reduced_muscles.osim").read_bytes())
    old = "<input_model_file>UF_Subject_3_reduced_muscles.osim</input_model_file>"
    assert old in text
    path = tmp_path / "CompletedSettingsFiles" / "MTPSettings.xml"
    path.parent.mkdir()
    path.write_text(text.replace(old, f"<input_model_file><!-- personalized -->{model}</input_model_file>", 1))
    (tmp_path / "preprocessed").mkdir()
    settings = StageSettings.from_file(path, MuscleTendonPersonalizationSettings)
    stage_file = tmp_path / "results" / "mtp" / "MTPSettings.xml"
    written = settings.text(stage_file, tmp_path / "results")
    assert "<input_model_file>../models/model.osim<!-- personalized -->" in written and str(model) not in written
    stage_file.parent.mkdir()
    stage_file.write_text(written)
    again = StageSettings.from_file(stage_file, MuscleTendonPersonalizationSettings)
    assert again.resolve(next(f for f in again.path_fields() if f.spec.element == "input_model_file")).resolve() == model

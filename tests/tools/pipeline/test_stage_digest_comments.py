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

"""A comment inside an `.osimx` value is not part of it and hides none of it (the value read
as '' and the file was refused: "'' is not a number")."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.io.osimx import read_osimx


@pytest.mark.shared_data
def test_comment_inside_a_value(shared_data: Path, tmp_path: Path) -> None:
    source = shared_data / "ncp" / "uf_subject3_tutorial" / "mtpResults" / "UF_Subject_3_reduced_muscles_mtp.osimx"
    text = source.read_text()
    old = "<tendon_slack_length>0.296035742385566</tendon_slack_length>"
    assert text.count(old) == 1
    path = tmp_path / "commented.osimx"
    path.write_text(text.replace(old, "<tendon_slack_length><!-- from MTP V3 -->0.296035742385566</tendon_slack_length>"))
    assert read_osimx(path).muscles == read_osimx(source).muscles

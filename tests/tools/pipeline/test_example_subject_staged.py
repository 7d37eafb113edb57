"""The example's synthetic subject is written through the results staging: a full disk (or a
kill) while it is generated leaves no subject that the next run would take as complete."""

from __future__ import annotations

import errno
import pathlib
from pathlib import Path

import pytest


def _full_disk_at(monkeypatch: pytest.MonkeyPatch, method: str, name: str) -> None:
    """``Path.<method>`` writes half of ``name``'s content, then the disk is full."""
    real = getattr(pathlib.Path, method)

    def half_then_full(self: Path, data, *args: object, **kwargs: object) -> int:
        if self.name == name:
            real(self, data[: len(data) // 2], *args, **kwargs)
            raise OSError(errno.ENOSPC, "No space left on device", str(self))
        return real(self, data, *args, **kwargs)

    monkeypatch.setattr(pathlib.Path, method, half_then_full)


def _nothing_left(folder: Path) -> None:
    from nmsm.examples.subject import subject_in

    assert subject_in(folder) is None
    assert not folder.exists() or list(folder.iterdir()) == []


def test_a_full_disk_while_writing_the_model_leaves_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from nmsm.examples.subject import make_subject

    _full_disk_at(monkeypatch, "write_bytes", "true.osim")
    with pytest.raises(OSError):
        make_subject(tmp_path / "example")
    _nothing_left(tmp_path / "example")


@pytest.mark.slow
def test_a_full_disk_while_writing_the_truth_leaves_no_subject(tmp_path: Path,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """The last file: before staging, a truncated ``truth.json`` beside a complete subject was
    taken as complete by the next run."""
    from nmsm.examples.subject import make_subject

    _full_disk_at(monkeypatch, "write_text", "truth.json")
    with pytest.raises(OSError):
        make_subject(tmp_path / "example")
    _nothing_left(tmp_path / "example")

"""``staged_outputs`` (nmsm/io/output_file.py): several files moved into place together; a
failure while they are moved puts the earlier files back."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.output_file import staged_outputs


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _write_three(folder: Path) -> None:
    with staged_outputs() as staged:
        stage = staged.folder(folder / "new")
        (stage / "sub").mkdir()
        for name in ("a.txt", "b.txt", "sub/c.txt"):
            (stage / name).write_text(f"new {name}\n")


@pytest.mark.parametrize("failing_move", range(1, 6))
def test_a_failed_move_puts_the_earlier_files_back(failing_move: int, tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    """Each of the five moves (a.txt and b.txt: the earlier file aside, the new one in; the
    new sub/c.txt in) fails in turn: the earlier files are back, no new file, backup or
    staging folder is left, and the folder created for the new files is removed."""
    (tmp_path / "new").mkdir()
    (tmp_path / "new" / "a.txt").write_text("earlier a\n")
    (tmp_path / "new" / "b.txt").write_text("earlier b\n")
    before = _files(tmp_path)
    real = os.replace
    moves: list[tuple[str, str]] = []

    def replace(src, dst) -> None:
        moves.append((str(src), str(dst)))
        if len(moves) == failing_move:
            raise OSError(28, "No space left on device", str(dst))
        real(src, dst)  # the moves after the failure put the earlier files back

    with monkeypatch.context() as patch:
        patch.setattr(os, "replace", replace)
        with pytest.raises(InputError, match="cannot write the output file: No space left on device"):
            _write_three(tmp_path)
    assert len(moves) >= failing_move
    assert _files(tmp_path) == before
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == ["a.txt", "b.txt"]  # no sub/, backup or stage
    _write_three(tmp_path)
    assert _files(tmp_path) == {"new/a.txt": b"new a.txt\n", "new/b.txt": b"new b.txt\n",
                                "new/sub/c.txt": b"new sub/c.txt\n"}
    assert sorted(p.name for p in (tmp_path / "new").iterdir()) == ["a.txt", "b.txt", "sub"]


def test_a_stop_while_writing_removes_the_folders_it_created(tmp_path: Path) -> None:
    with pytest.raises(KeyboardInterrupt):
        with staged_outputs() as staged:
            (staged.folder(tmp_path / "x" / "y") / "f.txt").write_text("f\n")
            (staged.file(tmp_path / "g.txt")).write_text("g\n")
            raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []

"""ResultsDirectory: staging per task, inputs protected, read-only trees refused."""

from __future__ import annotations

import os
import stat

import pytest

from nmsm.core.results import ResultsDirectory
from nmsm.errors import InputError


def test_finished_task_moves_files_in(tmp_path) -> None:
    results = ResultsDirectory(tmp_path / "out")
    with results.task("a") as stage:
        (stage / "sub").mkdir()
        (stage / "sub" / "x.txt").write_text("done")
    assert (tmp_path / "out" / "sub" / "x.txt").read_text() == "done"
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["sub"]


def test_failed_task_leaves_nothing(tmp_path) -> None:
    results = ResultsDirectory(tmp_path / "out")
    with results.task("ok") as stage:
        (stage / "first.txt").write_text("1")
    with pytest.raises(KeyboardInterrupt):
        with results.task("stopped") as stage:
            (stage / "half.txt").write_text("partial")
            raise KeyboardInterrupt
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["first.txt"]


def test_inputs_are_never_overwritten(tmp_path) -> None:
    model = tmp_path / "model.osim"
    model.write_text("<OpenSimDocument/>")
    results = ResultsDirectory(tmp_path, inputs=[model])
    with pytest.raises(InputError, match="overwrite an input"):
        with results.task("t") as stage:
            (stage / "model.osim").write_text("changed")
    assert model.read_text() == "<OpenSimDocument/>"


def test_read_only_tree_is_refused_even_for_root(tmp_path) -> None:
    locked = tmp_path / "shared"
    locked.mkdir()
    os.chmod(locked, stat.S_IRUSR | stat.S_IXUSR)
    try:
        with pytest.raises(InputError, match="read-only"):
            ResultsDirectory(locked / "results")
        assert not (locked / "results").exists()
    finally:
        os.chmod(locked, stat.S_IRWXU)

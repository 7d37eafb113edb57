"""ResultsDirectory: staging per task, inputs protected, read-only trees refused."""

from __future__ import annotations

import os
import stat
from pathlib import Path

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


def test_retire_moves_only_recorded_files(tmp_path) -> None:
    out = tmp_path / "out"
    settings = tmp_path / "out" / "settings.xml"
    out.mkdir()
    settings.write_text("<input/>")
    results = ResultsDirectory(out, inputs=[settings])
    with results.task("t", record="trial") as stage:
        (stage / "sub").mkdir()
        (stage / "sub" / "a.sto").write_text("run 1")
        (stage / "b.txt").write_text("run 1")
    (out / "notes.txt").write_text("the user's")
    assert sorted(results.recorded("trial")) == [Path("b.txt"), Path("sub/a.sto")]
    assert sorted(results.retire("trial")) == [Path("b.txt"), Path("sub/a.sto")]
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == ["notes.txt", "settings.xml",
                                                                                    "superseded"]
    assert (out / "superseded" / "sub" / "a.sto").read_text() == "run 1"
    assert results.retire("trial") == []  # nothing recorded any more
    assert settings.read_text() == "<input/>"


def test_recorded_task_retires_earlier_files_it_did_not_rewrite(tmp_path) -> None:
    results = ResultsDirectory(tmp_path)
    with results.task("t", record="trial") as stage:
        (stage / "a.txt").write_text("1")
        (stage / "old_only.txt").write_text("1")
    with results.task("t", record="trial") as stage:
        (stage / "a.txt").write_text("2")
    assert (tmp_path / "a.txt").read_text() == "2"
    assert not (tmp_path / "old_only.txt").exists()
    assert (tmp_path / "superseded" / "old_only.txt").read_text() == "1"
    assert results.recorded("trial") == [Path("a.txt")]


def test_record_never_reaches_outside_or_inputs(tmp_path) -> None:
    model = tmp_path / "model.osim"
    model.write_text("model")
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / ".nmsm-outputs-trial.txt").write_text("../model.osim\n" + str(model) + "\n")
    results = ResultsDirectory(tmp_path / "out", inputs=[model])
    assert results.retire("trial") == []
    assert model.read_text() == "model"

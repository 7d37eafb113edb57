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


def test_folder_is_created_by_the_first_task_and_removed_if_it_fails(tmp_path) -> None:
    results = ResultsDirectory(tmp_path / "a" / "b")
    assert not (tmp_path / "a").exists()
    with pytest.raises(ValueError):
        with results.task("t") as stage:
            (stage / "x.txt").write_text("half")
            raise ValueError("bad input")
    assert not (tmp_path / "a").exists()  # nothing left, not even empty folders
    with results.task("t") as stage:
        (stage / "x.txt").write_text("done")
    assert (tmp_path / "a" / "b" / "x.txt").read_text() == "done"


def test_a_failing_later_task_keeps_the_folder_and_finished_files(tmp_path) -> None:
    results = ResultsDirectory(tmp_path / "out")
    with results.task("one") as stage:
        (stage / "one.txt").write_text("1")
    with pytest.raises(ValueError):
        with results.task("two"):
            raise ValueError
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["one.txt"]


def test_input_folders_are_refused_before_anything_is_written(tmp_path) -> None:
    data = tmp_path / "preprocessed"
    (data / "IKData").mkdir(parents=True)
    folders = {"<data_directory> IKData": data / "IKData"}
    roots = {"<data_directory>": data}
    for target, where in [(data / "IKData", "is the"), (data / "IKData" / "run", "is inside the"), (data, "is the")]:
        with pytest.raises(InputError, match=f"{where} .*: the results would mix"):
            ResultsDirectory(target, input_folders=folders, input_roots=roots, settings_file=tmp_path / "s.xml")
    ResultsDirectory(data / "results", input_folders=folders, input_roots=roots)  # a new sub-folder of the root
    assert sorted(p.name for p in data.iterdir()) == ["IKData"]


def test_reserve_refuses_a_known_output_name_before_solving(tmp_path) -> None:
    model = tmp_path / "model.osim"
    model.write_text("<OpenSimDocument/>")
    results = ResultsDirectory(tmp_path, inputs=[model])
    with pytest.raises(InputError, match="model.osim would overwrite an input file") as info:
        results.reserve("model.osim", element="<output_model_file>")
    assert "<output_model_file>" in str(info.value)
    results.reserve("other.osim")


def test_copy_in_of_the_file_itself_does_nothing(tmp_path) -> None:
    settings = tmp_path / "settings.xml"
    settings.write_text("<settings/>")
    results = ResultsDirectory(tmp_path, inputs=[settings])
    assert results.copy_in(settings) == tmp_path / "settings.xml"
    assert settings.read_text() == "<settings/>"


def test_a_recorded_rerun_retires_the_earlier_run_and_sets_aside_other_files(tmp_path) -> None:
    out = tmp_path / "out"
    first = ResultsDirectory(out, record="mtp")
    with first.task("a") as stage:
        (stage / "Analysis").mkdir()
        (stage / "Analysis" / "synx.sto").write_text("run 1")
        (stage / "model_mtp.osimx").write_text("run 1")
    with first.task("b") as stage:  # a second task of the same run retires nothing
        (stage / "settings.xml").write_text("run 1")
    assert sorted(first.recorded("mtp")) == [Path("Analysis/synx.sto"), Path("model_mtp.osimx"), Path("settings.xml")]
    (out / "notes.txt").write_text("the user's")
    (out / "original.sto").write_text("the original tool's")
    second = ResultsDirectory(out, record="mtp")
    with pytest.warns(UserWarning) as caught:
        with second.task("a") as stage:
            (stage / "model_mtp.osimx").write_text("run 2")
            (stage / "original.sto").write_text("run 2")
    messages = " ".join(str(w.message) for w in caught)
    assert "3 files of the earlier mtp run" in messages and "original.sto" in messages
    assert (out / "model_mtp.osimx").read_text() == "run 2"
    assert not (out / "Analysis").exists()  # not looking like the second run's
    assert (out / "superseded" / "Analysis" / "synx.sto").read_text() == "run 1"
    assert (out / "superseded" / "replaced" / "original.sto").read_text() == "the original tool's"
    assert (out / "notes.txt").read_text() == "the user's"
    assert sorted(second.recorded("mtp")) == [Path("model_mtp.osimx"), Path("original.sto")]


@pytest.mark.parametrize("failing_move", [1, 2, 3])
def test_a_stop_while_moving_a_task_in_leaves_the_earlier_files(failing_move: int, tmp_path: Path,
                                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """A task's files are moved in all or none: a stop (Ctrl-C) at any of the moves (the earlier
    a.txt aside, the new a.txt in, the new b.txt in) leaves the earlier run's a.txt and no
    new file, backup or staging folder."""
    results = ResultsDirectory(tmp_path / "out")
    with results.task("first") as stage:
        (stage / "a.txt").write_text("earlier")
    real = os.replace
    calls: list[str] = []

    def replace(src, dst) -> None:
        calls.append(str(dst))
        if len(calls) == failing_move:
            raise KeyboardInterrupt
        real(src, dst)

    with pytest.raises(KeyboardInterrupt):
        with monkeypatch.context() as patch:
            patch.setattr(os, "replace", replace)
            with results.task("second") as stage:
                (stage / "a.txt").write_text("new")
                (stage / "b.txt").write_text("new")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.txt"]
    assert (tmp_path / "out" / "a.txt").read_text() == "earlier"


def test_a_stop_while_moving_leaves_no_new_folders(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A recorded run's task with files in new sub-folders, stopped at its second move: the
    sub-folders it created are removed again (none was left empty)."""
    results = ResultsDirectory(tmp_path / "out", record="tool")
    with results.task("first") as stage:
        (stage / "kept.txt").write_text("earlier")
    real = os.replace
    calls: list[str] = []

    def replace(src, dst) -> None:
        calls.append(str(dst))
        if len(calls) == 3:  # after the earlier run's file was retired and deep/a.txt moved
            raise KeyboardInterrupt
        real(src, dst)

    with pytest.raises(KeyboardInterrupt):
        with monkeypatch.context() as patch:
            patch.setattr(os, "replace", replace)
            with ResultsDirectory(tmp_path / "out", record="tool").task("second") as stage:
                (stage / "deep" / "er").mkdir(parents=True)
                (stage / "deep" / "er" / "a.txt").write_text("new")
                (stage / "z.txt").write_text("new")
    assert not (tmp_path / "out" / "deep").exists()
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".staging")]


def test_a_folder_where_a_result_file_goes_is_refused(tmp_path: Path) -> None:
    """A user's folder named like a result file: refused naming it, nothing moved or hidden."""
    (tmp_path / "out" / "a.txt").mkdir(parents=True)
    (tmp_path / "out" / "a.txt" / "inner.dat").write_text("user")
    with pytest.raises(InputError, match=r"out/a.txt: cannot write the output file: a folder of that name exists"):
        with ResultsDirectory(tmp_path / "out").task("t") as stage:
            (stage / "a.txt").write_text("result")
            (stage / "b.txt").write_text("result")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a.txt"]
    assert (tmp_path / "out" / "a.txt" / "inner.dat").read_text() == "user"


def test_a_file_where_a_result_folder_goes_is_named(tmp_path: Path) -> None:
    """``b`` is a file where the results need a folder ``b/``: the error names ``b/c.txt``, not
    the file moved before it; the earlier move is undone."""
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "b").write_text("user")
    with pytest.raises(InputError, match=r"out/b/c.txt: cannot write the output file: Not a directory"):
        with ResultsDirectory(tmp_path / "out").task("t") as stage:
            (stage / "a.txt").write_text("result")
            (stage / "b").mkdir()
            (stage / "b" / "c.txt").write_text("result")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["b"]

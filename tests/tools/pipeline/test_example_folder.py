"""``nmsm example --folder DIR [--rebuild]``: the folder the example may delete.

The example marks a folder it creates (:data:`nmsm.examples.example_run.MARKER`); ``--rebuild``
deletes only a marked folder. Nothing here runs the example's stages (each case fails, or is
checked, before the subject is generated).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.examples.example_run import MARKER, prepare_example_folder, run_example


def test_rebuild_keeps_a_folder_the_example_did_not_create(tmp_path: Path) -> None:
    folder = tmp_path / "userdir"
    folder.mkdir()
    (folder / "important.txt").write_text("mine")
    with pytest.raises(InputError) as caught:
        run_example(folder, until="jmp", rebuild=True, log=None)
    message = str(caught.value)
    assert str(folder) in message and "important.txt" in message and "not a folder created by `nmsm example`" in message
    assert (folder / "important.txt").read_text() == "mine"
    assert sorted(p.name for p in folder.iterdir()) == ["important.txt"]  # nothing deleted, nothing added


def test_rebuild_names_a_few_entries_then_how_many_more(tmp_path: Path) -> None:
    for k in range(7):
        (tmp_path / f"file{k}.txt").write_text("x")
    with pytest.raises(InputError, match=r"file0\.txt, file1\.txt, file2\.txt, file3\.txt and 3 more"):
        prepare_example_folder(tmp_path, rebuild=True)
    assert len(list(tmp_path.iterdir())) == 7


def test_rebuild_refuses_an_older_example_folder_without_the_marker(tmp_path: Path) -> None:
    for name in ("subject", "truth", "results"):
        (tmp_path / name).mkdir()
    (tmp_path / "pipeline.xml").write_text("<x/>")
    with pytest.raises(InputError, match="older nmsm.*delete it by hand"):
        prepare_example_folder(tmp_path, rebuild=True)
    assert (tmp_path / "subject").is_dir() and (tmp_path / "pipeline.xml").is_file()


def test_a_new_or_empty_folder_is_marked_and_rebuild_deletes_it(tmp_path: Path) -> None:
    new = prepare_example_folder(tmp_path / "a" / "new")
    assert (new / MARKER).is_file()
    (new / "subject").mkdir()
    (new / "subject" / "old.trc").write_text("x")
    again = prepare_example_folder(new, rebuild=True)
    assert sorted(p.name for p in again.iterdir()) == [MARKER]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert (prepare_example_folder(empty) / MARKER).is_file()


def test_a_folder_with_other_contents_is_used_but_not_marked(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("x")
    prepare_example_folder(tmp_path)
    assert not (tmp_path / MARKER).exists()


def test_rebuild_never_deletes_the_current_folder(tmp_path: Path, monkeypatch) -> None:
    folder = prepare_example_folder(tmp_path / "ex")
    (folder / "subject").mkdir()
    monkeypatch.chdir(folder)
    with pytest.raises(InputError, match="current working folder"):
        prepare_example_folder(".", rebuild=True)
    assert (folder / "subject").is_dir()


def test_folder_naming_a_file_is_an_input_error(tmp_path: Path, capsys) -> None:
    target = tmp_path / "afile"
    target.write_text("x")
    with pytest.raises(InputError, match="is a file, not a folder"):
        run_example(target, until="jmp", log=None)
    with pytest.raises(InputError, match="which is a file, not a folder"):
        prepare_example_folder(target / "below")
    assert main(["example", "jmp", "--folder", str(target)]) == 1
    assert "is a file, not a folder" in capsys.readouterr().err
    assert target.read_text() == "x"

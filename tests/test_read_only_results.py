"""``nmsm report`` and ``nmsm plot`` without ``-o`` write into the results folder they read
(``report.html``, ``<folder>/plots``). A read-only results folder (the shipped original
results: ``chmod a-w``) is refused with one clear error, and nothing is written, even when
running as root (who may write a folder without write permission bits)."""

from __future__ import annotations

import shutil
import stat
from pathlib import Path

import pytest

from nmsm.cli import main

MTP_RESULTS = Path("mtp") / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "MTPResultsV1"


def _read_only_copy(shared_data: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "MTPResultsV1"
    shutil.copytree(shared_data / MTP_RESULTS, copy)
    for path in [copy, *copy.rglob("*")]:
        path.chmod(path.stat().st_mode & ~(stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH))
    return copy


def _tree(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize("command", ["report", "plot"])
def test_default_output_into_a_read_only_results_folder_is_refused(command, shared_data, tmp_path, capsys):
    folder = _read_only_copy(shared_data, tmp_path)
    before = _tree(folder)
    try:
        assert main([command, str(folder)]) != 0
        err = capsys.readouterr().err
        assert "is read-only" in err and "-o" in err and "nothing was written" in err
        assert _tree(folder) == before
    finally:
        for path in [folder, *folder.rglob("*")]:
            path.chmod(path.stat().st_mode | stat.S_IWUSR)


def test_report_of_a_read_only_results_folder_with_o_writes_elsewhere(shared_data, tmp_path, capsys):
    folder = _read_only_copy(shared_data, tmp_path)
    before = _tree(folder)
    out = tmp_path / "out.html"
    try:
        assert main(["report", str(folder), "-o", str(out)]) == 0
        assert out.stat().st_size > 0 and _tree(folder) == before
    finally:
        for path in [folder, *folder.rglob("*")]:
            path.chmod(path.stat().st_mode | stat.S_IWUSR)

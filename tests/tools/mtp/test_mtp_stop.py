"""A stop (Ctrl-C) during an MTP task keeps the tasks finished before it
(``<results>/stopped_after_task_<k>/``), never as if the run had finished."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

import nmsm.tools.mtp.run as mtp_run


def _two_task_settings(shared_data: Path, tmp_path: Path) -> Path:
    """Tutorial V3 with its one task twice (a copy of the tutorial, writable)."""
    tutorial = tmp_path / "mtp"
    shutil.copytree(shared_data / "mtp" / "uf_subject3_tutorial", tutorial)
    for path in [tutorial, *tutorial.rglob("*")]:
        path.chmod(path.stat().st_mode | 0o200)
    settings = tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml"
    text = settings.read_text()
    start, end = text.index("<MTPTask>"), text.index("</MTPTask>") + len("</MTPTask>")
    target = settings.with_name("two_tasks.xml")
    second = text[start:end]
    assert "<index>1</index>" in second
    target.write_text(text[:end] + second.replace("<index>1</index>", "<index>2</index>") + text[end:])
    return target


def test_stop_during_the_second_task_keeps_the_first(shared_data: Path, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Run A finishes; rerun B is stopped in task 2: B's results after task 1 go into
    ``stopped_after_task_1/`` and A's files stay at the top, unchanged; run C (to the end)
    retires both into ``superseded/``."""
    settings = _two_task_settings(shared_data, tmp_path)
    out = tmp_path / "results"
    osimx = "UF_Subject_3_reduced_muscles_mtp.osimx"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mtp_run.run_settings(settings, results_directory=out)  # A
    complete = _files(out)
    a_osimx = (out / osimx).read_bytes()
    real = mtp_run.solve_task_problem
    calls = []

    def stopped_in_the_second(problem, **options):
        calls.append(problem)
        if len(calls) == 2:
            raise KeyboardInterrupt  # as nmsm.core.interrupts raises after IPOPT returns
        return real(problem, **options)

    monkeypatch.setattr(mtp_run, "solve_task_problem", stopped_in_the_second)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(KeyboardInterrupt):
            mtp_run.run_settings(settings, results_directory=out)  # B
    kept = out / "stopped_after_task_1"
    assert "results after task 1 are in" in capsys.readouterr().err
    assert (out / osimx).read_bytes() == a_osimx and not (out / "superseded").exists()  # A untouched
    summary = (kept / "mtpSummary.txt").read_text().splitlines()
    assert summary[0] == "stopped during task 2 of 2: results after task 1"
    assert summary[1].startswith("task 1: Solve_Succeeded")
    stopped = sorted(p.relative_to(kept).as_posix() for p in kept.rglob("*") if p.is_file())
    assert stopped == [f for f in complete if f != settings.name and not f.startswith("stopped_after")]
    monkeypatch.setattr(mtp_run, "solve_task_problem", real)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mtp_run.run_settings(settings, results_directory=out)  # C
    assert not kept.exists()
    assert (out / "superseded" / "stopped_after_task_1" / "mtpSummary.txt").is_file()
    assert (out / "superseded" / osimx).read_bytes() == a_osimx
    assert _files(out) == complete


def _files(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*")
                  if p.is_file() and not p.name.startswith(".") and p.relative_to(folder).parts[0] != "superseded")


def test_stop_during_the_first_task_writes_nothing(shared_data: Path, tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    settings = _two_task_settings(shared_data, tmp_path)
    out = tmp_path / "results"

    def stopped(problem, **options):
        raise KeyboardInterrupt

    monkeypatch.setattr(mtp_run, "solve_task_problem", stopped)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(KeyboardInterrupt):
            mtp_run.run_settings(settings, results_directory=out)
    assert not out.exists()


def test_pipeline_stage_option_keeps_nothing(shared_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    """``keep_finished_on_stop=False`` (the pipeline's MTP stage, whose stopped folder the
    runner discards): nothing written and no message pointing at a folder."""
    from nmsm.tools.pipeline.kinds import kind_for_element

    assert kind_for_element("MuscleTendonPersonalizationTool").run_options == {"keep_finished_on_stop": False}
    settings = _two_task_settings(shared_data, tmp_path)
    out = tmp_path / "results"
    real = mtp_run.solve_task_problem
    calls = []

    def stopped_in_the_second(problem, **options):
        calls.append(problem)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(problem, **options)

    monkeypatch.setattr(mtp_run, "solve_task_problem", stopped_in_the_second)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(KeyboardInterrupt):
            mtp_run.run_settings(settings, results_directory=out, keep_finished_on_stop=False)
    assert not out.exists() and "results after task" not in capsys.readouterr().err

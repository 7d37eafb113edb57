"""A stop (Ctrl-C) during a GCP task keeps the tasks finished before it
(``<results>/stopped_after_task_<k>/``), never as if the run had finished."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import nmsm.tools.gcp.run as gcp_run

SETTINGS = "gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPSettingsV1.xml"  # three tasks


def _files(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*")
                  if p.is_file() and not p.name.startswith(".") and p.relative_to(folder).parts[0] != "superseded")


def _stop_in_call(monkeypatch: pytest.MonkeyPatch, n: int) -> None:
    real = gcp_run.solve_task
    calls = []

    def solve(built, **options):
        calls.append(built)
        if len(calls) == n:
            raise KeyboardInterrupt  # a Ctrl-C inside the least-squares solve
        return real(built, **options)

    monkeypatch.setattr(gcp_run, "solve_task", solve)


def _run(settings: Path, out: Path, **options) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gcp_run.run_settings(settings, results_directory=out, max_iterations=2, accept_unconverged=True, **options)


def test_stop_during_the_third_task_keeps_the_second(shared_data: Path, tmp_path: Path,
                                                     monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """Run A finishes; rerun B is stopped in task 3: its results after task 2 go into
    ``stopped_after_task_2/`` and A's files stay at the top, unchanged; run C retires both."""
    settings, out = shared_data / SETTINGS, tmp_path / "gcp"
    _run(settings, out)  # A
    complete = _files(out)
    a_osimx = (out / "bodyModel_gcp.osimx").read_bytes()
    _stop_in_call(monkeypatch, 3)
    with pytest.raises(KeyboardInterrupt):
        _run(settings, out)  # B
    assert "the results after task 2 are in" in capsys.readouterr().err
    kept = out / "stopped_after_task_2"
    assert (out / "bodyModel_gcp.osimx").read_bytes() == a_osimx and not (out / "superseded").exists()
    log = (kept / "commandWindowOutput.txt").read_text().splitlines()
    assert log[1] == "stopped during task 3 of 3: results after task 2"
    assert [line.split(" (")[0] for line in log if line.startswith("task ")] == ["task 1", "task 2"]
    assert _files(kept) == [f for f in complete if f != settings.name]  # what a finished run writes
    monkeypatch.undo()
    _run(settings, out)  # C
    assert not kept.exists() and (out / "superseded" / kept.name / "commandWindowOutput.txt").is_file()
    assert (out / "superseded" / "bodyModel_gcp.osimx").read_bytes() == a_osimx
    assert _files(out) == complete


@pytest.mark.parametrize("options", [{}, {"keep_finished_on_stop": False}])
def test_stop_before_a_finished_task_or_in_a_pipeline_writes_nothing(shared_data: Path, tmp_path: Path,
                                                                     monkeypatch: pytest.MonkeyPatch,
                                                                     options: dict) -> None:
    """Stopped in task 1 nothing is written; with ``keep_finished_on_stop=False`` (the
    pipeline's stage: the runner discards a stopped stage's folder) not after task 2 either."""
    from nmsm.tools.pipeline.kinds import kind_for_element

    assert kind_for_element("GroundContactPersonalizationTool").run_options == {"keep_finished_on_stop": False}
    _stop_in_call(monkeypatch, 3 if options else 1)
    out = tmp_path / "gcp"
    with pytest.raises(KeyboardInterrupt):
        _run(shared_data / SETTINGS, out, **options)
    assert not out.exists()

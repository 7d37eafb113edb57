"""``nmsm batch`` on a real LocalCluster of 2 worker processes, with JMP runs of a synthetic case:
parallel runs and dependencies, a broken settings file failing alone, a rerun skipping every
finished run, a worker killed mid-run, Ctrl-C."""

from __future__ import annotations

import json
import os
import signal
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from batch_helpers import leftover_processes, sweep, write_batch  # noqa: E402

from nmsm.batch import run  # noqa: E402
from nmsm.batch.execute import LOCAL_CLUSTER_CONFIG, connect  # noqa: E402
from nmsm.batch.summary import read_summary  # noqa: E402


def _events(log: list):
    return lambda kind, name, details: log.append((kind, name, details))


def test_runs_wait_for_their_dependencies_a_broken_file_fails_alone_and_a_rerun_skips_them(
        jmp_case, tmp_path, time_limit) -> None:
    time_limit(240)
    settings, broken = jmp_case.settings_file, jmp_case.folder / "broken.xml"
    batch = write_batch(tmp_path, f"""\
        <Run name="base"><settings_file>{settings}</settings_file></Run>
        <Run name="broken"><settings_file>{broken}</settings_file></Run>
        {sweep(settings, extra="<depends_on>base</depends_on>")}""")
    events: list = []
    first = run(batch, workers=2, log=None, on_event=_events(events))
    status = {name: o.status for name, o in first.outcomes.items()}
    assert status == {"base": "ok", "broken": "failed", "bounds/knee_bounds=0.2": "ok",
                      "bounds/knee_bounds=0.5": "ok"}, first.text()
    message = first.outcomes["broken"].message
    assert "broken.xml" in message and "'lots' is not an integer" in message
    order = [(kind, name) for kind, name, _ in events]
    assert ("started", "broken") not in order  # refused before it reached a worker
    assert order.index(("finished", "base")) < order.index(("started", "bounds/knee_bounds=0.2"))
    assert order.index(("finished", "base")) < order.index(("started", "bounds/knee_bounds=0.5"))
    out = tmp_path / "out"
    for name in ("base", "bounds/knee_bounds=0.2", "bounds/knee_bounds=0.5"):
        assert (out / name / "personalized.osim").is_file(), name
        assert (out / f"{name}.xml").is_file()
    settings_copy = (out / "bounds" / "knee_bounds=0.2.xml").read_text(encoding="utf-8")
    assert "<orientation_bounds>0.2</orientation_bounds>" in settings_copy
    columns, rows = read_summary(first.summary_file)
    assert [r["run"] for r in rows] == list(status)
    assert "knee_bounds" in columns
    assert [r["knee_bounds"] for r in rows] == ["", "", "0.2", "0.5"]
    assert all(r["iterations"] and r["objective"] and r["worker"] for r in rows if r["status"] == "ok")
    assert all(float(r["cpu_time_s"]) > 0 for r in rows if r["status"] == "ok")
    assert (out / "plots" / "sweep_bounds.png").is_file()
    assert not leftover_processes()

    events.clear()
    second = run(batch, workers=2, log=None, on_event=_events(events))
    assert {name: o.status for name, o in second.outcomes.items()} == {
        "base": "skipped", "broken": "failed", "bounds/knee_bounds=0.2": "skipped",
        "bounds/knee_bounds=0.5": "skipped"}
    assert not [e for e in events if e[0] == "started"]
    assert second.workers == 0  # no run needed a worker: no cluster was started
    _, rows = read_summary(second.summary_file)
    assert all(r["objective"] for r in rows if r["status"] == "skipped")


def test_a_worker_killed_mid_run_has_its_run_retried_and_the_batch_completes(long_jmp_case, tmp_path,
                                                                            time_limit) -> None:
    time_limit(240)
    batch = write_batch(tmp_path, sweep(long_jmp_case.settings_file))
    killed: list[tuple[str, int]] = []
    started: list[str] = []

    def kill_first(kind, name, details):
        if kind != "started":
            return
        started.append(name)
        if not killed:
            killed.append((name, details["pid"]))
            os.kill(details["pid"], signal.SIGKILL)

    outcome = run(batch, workers=2, log=None, on_event=kill_first)
    assert killed
    victim = killed[0][0]
    assert {o.status for o in outcome.outcomes.values()} == {"ok"}, outcome.text()
    assert outcome.outcomes[victim].attempts == 2
    assert started.count(victim) == 2
    assert (tmp_path / "out" / victim / "personalized.osim").is_file()
    assert not (tmp_path / "out" / ".nmsm-batch" / f"{victim}.attempt.json").exists()
    record = json.loads((tmp_path / "out" / ".nmsm-batch" / f"{victim}.json").read_text(encoding="utf-8"))
    assert record["outcome"]["attempts"] == 2
    _, rows = read_summary(outcome.summary_file)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert not leftover_processes()


def test_ctrl_c_keeps_the_finished_runs_and_writes_the_summary(jmp_case, tmp_path, time_limit) -> None:
    time_limit(180)
    settings = jmp_case.settings_file
    batch = write_batch(tmp_path, f"""\
        <Run name="base"><settings_file>{settings}</settings_file></Run>
        {sweep(settings, values="0.3", extra="<depends_on>base</depends_on>")}""")

    def stop_after_base(kind, name, details):
        if kind == "finished" and name == "base":
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run(batch, workers=1, log=None, on_event=stop_after_base)
    out = tmp_path / "out"
    assert (out / "base" / "personalized.osim").is_file()
    assert (out / ".nmsm-batch" / "base.json").is_file()
    _, rows = read_summary(out / "batch_summary.csv")
    assert [(r["run"], r["status"]) for r in rows] == [("base", "ok"), ("bounds/knee_bounds=0.3", "stopped")]
    assert not (out / "bounds").exists()
    assert not leftover_processes()


def _worker_settings() -> dict:
    import dask

    from nmsm.core.threads import SOLVER_THREADS

    return {"config": {key: dask.config.get(key) for key in LOCAL_CLUSTER_CONFIG}, "solver_threads": SOLVER_THREADS,
            "threads": {name: os.environ.get(name) for name in ("NMSM_THREADS", "OMP_NUM_THREADS",
                                                                 "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}}


def test_the_local_cluster_runs_single_threaded_solves_with_light_bookkeeping(time_limit) -> None:
    time_limit(120)
    with connect(2, None, 60) as (client, count, _, local):
        settings = client.run(_worker_settings)
        saturation = client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.WORKER_SATURATION)
    assert count == 2 and local and len(settings) == 2
    for worker in settings.values():
        assert worker["config"] == LOCAL_CLUSTER_CONFIG
        assert worker["solver_threads"] == 1 and set(worker["threads"].values()) == {"1"}, worker
    assert saturation == LOCAL_CLUSTER_CONFIG["distributed.scheduler.worker-saturation"] == 1.0
    assert not leftover_processes()

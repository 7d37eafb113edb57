"""One run on a worker: :func:`run_one` (what Dask executes).

A settings run writes its settings to ``<results>/<run>.xml`` and runs them with
:func:`nmsm.run` (the tool stages its results, :mod:`nmsm.core.results`); a pipeline run runs
its pipeline file with the pipeline runner into ``<results>/<run>/``
(:mod:`nmsm.tools.pipeline.runner`, which skips its stages that are up to date).

The batch keeps its own records in ``<results>/.nmsm-batch/``:

* ``<run>.attempt.json`` while the run runs (worker, process id, start time);
* ``<run>.earlier/``: a settings run's earlier results, settings copy and record while it
  runs again; put back if it is stopped; if it fails, the earlier results and record are put
  back (the failed attempt's settings copy stays: the message may name it), or, when the
  failure wrote a last iterate, that stays and the earlier results go into its
  ``superseded/``; removed once it finished;
* ``<run>.json`` once it finished: the digest of its inputs (:func:`nmsm.batch.execute.input_digest`),
  the digest of its results folder and its outcome, so a rerun with the same inputs skips it
  (a pipeline run is skipped when its runner finds every stage up to date); once it failed,
  its outcome (never skipped).

A worker that dies mid-run leaves the attempt record: the next attempt (the scheduler
retries the run on another worker, or a later ``nmsm batch``) removes what the dead one
wrote and puts the earlier results back first (:func:`recover`), and counts the attempt.
"""

from __future__ import annotations

import datetime
import json
import os
import shutil
import socket
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.batch.outcome import FAILED, OK, SKIPPED, RunOutcome
from nmsm.batch.sweep import RunPlan
from nmsm.errors import NmsmError

ADMIN = ".nmsm-batch"
#: Dask event topic of the "run started" messages (:func:`run_one`)
EVENT_TOPIC = "nmsm-batch"
#: warnings of a run kept in its outcome
KEPT_WARNINGS = 5


def admin_path(plan: RunPlan, suffix: str) -> Path:
    """``<results>/.nmsm-batch/<run name><suffix>``."""
    return plan.results_root / ADMIN / f"{plan.name}{suffix}"


def record_path(plan: RunPlan) -> Path:
    return admin_path(plan, ".json")


def read_record(plan: RunPlan) -> dict[str, Any] | None:
    """The finished run's record, or None (none, or unreadable)."""
    try:
        return json.loads(record_path(plan).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def owns_folder(plan: RunPlan) -> bool:
    """Whether the batch wrote the run's folder (a record, an attempt or an aside copy)."""
    return any(admin_path(plan, s).exists() for s in (".json", ".attempt.json", ".earlier"))


def _write_json(path: Path, data: dict[str, Any]) -> None:
    from nmsm.io.output_file import write_output

    path.parent.mkdir(parents=True, exist_ok=True)
    write_output(path, json.dumps(data, indent=1) + "\n")


def _parts(plan: RunPlan) -> tuple[tuple[Path, str], ...]:
    """What a settings run's earlier state is made of, and its name in the aside folder."""
    return ((plan.folder, "results"), (plan.settings_copy, "settings.xml"), (record_path(plan), "record.json"))


def _remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


def _put_back(plan: RunPlan, names: tuple[str, ...] = ("results", "settings.xml", "record.json")) -> None:
    """Remove what the current attempt wrote of ``names`` and move the earlier ones back from
    the aside folder (removed afterwards)."""
    aside = admin_path(plan, ".earlier")
    for path, name in _parts(plan):
        if name in names:
            _remove(path)
            if (aside / name).exists():
                path.parent.mkdir(parents=True, exist_ok=True)
                (aside / name).rename(path)
    if aside.exists():
        shutil.rmtree(aside)


def recover(plan: RunPlan) -> bool:
    """Undo what an interrupted attempt left (module docstring); whether there was one."""
    attempt = admin_path(plan, ".attempt.json")
    interrupted = attempt.exists()
    if plan.kind == "settings" and (interrupted or admin_path(plan, ".earlier").exists()):
        _put_back(plan)
    attempt.unlink(missing_ok=True)
    return interrupted


def _worker() -> tuple[str, Any]:
    """(the worker's address, or host:pid outside Dask; the Dask worker or None)."""
    try:
        from distributed import get_worker

        worker = get_worker()
        return str(worker.address), worker
    except (ImportError, ValueError):
        return f"{socket.gethostname()}:{os.getpid()}", None


def _tracking_rms(folder: Path) -> float | None:
    """RMS over time and coordinates of modeled minus tracked coordinates in a treatment
    results folder's ``Analysis/`` (degrees, as the report's tracking table), or None."""
    from nmsm.io.storage import read_storage

    errors = []
    modeled = sorted((folder / "Analysis").glob("*_modeledPositions.sto"))
    for m_file in modeled:
        t_file = m_file.with_name(m_file.name.replace("_modeledPositions", "_trackedPositions"))
        if not t_file.is_file():
            continue
        m, t = read_storage(m_file), read_storage(t_file)
        for label in m.labels:
            if t.has(label):
                error = m.column(label) - t.column(label)
                errors.append(error if m.in_degrees else np.degrees(error))
    if not errors:
        return None
    return float(np.sqrt(np.mean(np.concatenate(errors) ** 2)))


def headline(result: Any, folder: Path) -> dict[str, Any]:
    """The figures of a tool's result (duck-typed: ``solution``, the last task's, ``initial_cost``)."""
    from nmsm.tools.pipeline.runner import PipelineRun

    if isinstance(result, PipelineRun):
        ran = [s for s in result.stages if s.result is not None]
        return headline(ran[-1].result, ran[-1].results_directory) if ran else {}
    solution = getattr(result, "solution", None)
    if solution is None and getattr(result, "tasks", None):
        solution = getattr(result.tasks[-1], "solution", None)
    figures: dict[str, Any] = {"tracking_rms": _tracking_rms(folder)}
    if solution is not None:
        figures.update(ipopt_status=str(getattr(solution, "status", "")),
                       iterations=getattr(solution, "iterations", None),
                       objective=getattr(solution, "cost", None))
    if getattr(result, "initial_cost", None) is not None:
        figures["initial_objective"] = result.initial_cost
    return figures


def _run_settings(plan: RunPlan) -> Any:
    import nmsm
    from nmsm.batch.sweep import settings_text, tool_kind

    text = settings_text(plan)
    plan.settings_copy.parent.mkdir(parents=True, exist_ok=True)
    from nmsm.io.output_file import write_output

    write_output(plan.settings_copy, text)
    return nmsm.run(plan.settings_copy, **tool_kind(plan.source).run_options)


def _run_pipeline(plan: RunPlan) -> Any:
    import attrs

    from nmsm.tools.pipeline.pipeline_file import read_pipeline
    from nmsm.tools.pipeline.runner import run_pipeline

    spec = attrs.evolve(read_pipeline(plan.source), results_directory=plan.folder)
    return run_pipeline(spec, log=None)


def _set_aside(plan: RunPlan) -> None:
    """Move a settings run's earlier results, settings copy and record into the aside folder."""
    if plan.kind != "settings":
        record_path(plan).unlink(missing_ok=True)
        return
    aside = admin_path(plan, ".earlier")
    aside.mkdir(parents=True)
    for path, name in _parts(plan):
        if path.exists():
            path.rename(aside / name)


def _after_failure(plan: RunPlan, exc: BaseException) -> bool:
    """After a failed attempt: keep a last iterate (its folder and settings copy; the earlier
    results go into its ``superseded/``), or remove the partial results and put the earlier
    results and record back (the attempt's settings copy stays: the message may name it).
    Returns whether an earlier record is back."""
    if plan.kind != "settings":
        return False
    aside = admin_path(plan, ".earlier")
    if getattr(exc, "last_iterate_path", None) is not None and plan.folder.exists():
        if (aside / "results").exists():
            target = plan.folder / "superseded" / "earlier_batch_run"
            target.parent.mkdir(parents=True, exist_ok=True)
            (aside / "results").rename(target)
        shutil.rmtree(aside, ignore_errors=True)
        return False
    had_record = (aside / "record.json").exists()
    _put_back(plan, ("results", "record.json"))
    return had_record


def _all_up_to_date(result: Any) -> bool:
    from nmsm.tools.pipeline.runner import RAN

    return not any(s.status == RAN for s in getattr(result, "stages", ()))


def run_one(plan: RunPlan, digest: str | None) -> RunOutcome:
    """Run ``plan`` (module docstring); ``digest``: its input digest, recorded when it
    finishes (None: a pipeline run, whose runner keeps its stages up to date). A failure
    is the outcome's message; Ctrl-C (KeyboardInterrupt) and a dying process are not caught."""
    from nmsm.tools.pipeline.hashing import DigestCache

    began, cpu_began = time.perf_counter(), time.process_time()
    address, worker = _worker()
    if worker is not None:
        worker.log_event(EVENT_TOPIC, {"run": plan.name, "pid": os.getpid(), "worker": address})
    attempts = 2 if recover(plan) else 1
    _set_aside(plan)
    _write_json(admin_path(plan, ".attempt.json"), {
        "run": plan.name, "worker": address, "pid": os.getpid(),
        "started": datetime.datetime.now().isoformat(timespec="seconds")})
    caught: list[str] = []
    try:
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("default")
            try:
                result = _run_pipeline(plan) if plan.kind == "pipeline" else _run_settings(plan)
            finally:
                caught = list(dict.fromkeys(str(w.message) for w in seen))[:KEPT_WARNINGS]
    except Exception as exc:  # noqa: BLE001 - one failing run is its outcome, the batch goes on
        message = str(exc) if isinstance(exc, NmsmError) else f"{type(exc).__name__}: {exc}"
        outcome = RunOutcome(plan.name, FAILED, message=message, wall_time=time.perf_counter() - began,
                             cpu_time=time.process_time() - cpu_began, worker=address, attempts=attempts,
                             warnings=tuple(caught))
        if not _after_failure(plan, exc):  # the record keeps the folder the batch's (never skipped)
            _write_json(record_path(plan), {"run": plan.name, "input_digest": None,
                                            "finished": datetime.datetime.now().isoformat(timespec="seconds"),
                                            "outcome": outcome.to_json()})
        admin_path(plan, ".attempt.json").unlink(missing_ok=True)
        return outcome
    except BaseException:  # Ctrl-C: nothing of this attempt stays
        recover(plan)
        raise
    shutil.rmtree(admin_path(plan, ".earlier"), ignore_errors=True)
    status = SKIPPED if plan.kind == "pipeline" and _all_up_to_date(result) else OK
    outcome = RunOutcome(plan.name, status, wall_time=time.perf_counter() - began,
                         cpu_time=time.process_time() - cpu_began, worker=address,
                         attempts=attempts, warnings=tuple(caught), **headline(result, plan.folder))
    _write_json(record_path(plan), {"run": plan.name, "input_digest": digest,
                                    "output_digest": DigestCache().folder(plan.folder),
                                    "finished": datetime.datetime.now().isoformat(timespec="seconds"),
                                    "outcome": outcome.to_json()})
    admin_path(plan, ".attempt.json").unlink(missing_ok=True)
    return outcome

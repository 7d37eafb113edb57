"""Running a batch on Dask distributed: :func:`run_batch` (``nmsm batch``, :func:`nmsm.batch.run`).

1. Read the batch file, expand its sweeps, link dependencies and warm starts, and check
   every run's settings (:mod:`nmsm.batch.batch_file`, :mod:`nmsm.batch.sweep`,
   :mod:`nmsm.batch.graph`); a results folder the batch did not write is refused. Any of
   these errors stops the batch before a run starts.
2. Connect: without ``scheduler``, a :class:`distributed.LocalCluster` of ``workers`` worker
   processes (default: one per core) with one thread each, their solves single-threaded
   (``NMSM_THREADS=1``; OpenMP/BLAS at 1 thread, Dask's default), the scheduler retrying a
   run whose worker died once (:data:`RETRIES`), Dask's bookkeeping light
   (:data:`LOCAL_CLUSTER_CONFIG`); with ``scheduler``, the user's cluster at
   that address (refused when it does not answer within ``timeout`` seconds).
3. Submit each run once the runs it depends on finished (:func:`nmsm.batch.task.run_one` on
   a worker). A run whose inputs (settings, the contents of every file and folder they name,
   nmsm's code) have the digest recorded when it last finished, and whose results folder is
   unchanged, is skipped. A run that fails is a ``failed`` row; the runs that depend on it
   are ``not run``; the others go on. Ctrl-C stops the batch: finished runs stay, the
   summary is written, the interrupted runs' earlier results are put back.
4. Write ``<results>/batch_summary.csv`` and ``<results>/plots/sweep_<name>.png``
   (:mod:`nmsm.batch.summary`).
"""

from __future__ import annotations

import contextlib
import importlib.util
import logging
import os
import queue
import shutil
import time
import uuid
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import attrs

from nmsm.batch.batch_file import BatchSpec, read_batch
from nmsm.batch.graph import link, order
from nmsm.batch.outcome import FAILED, FINISHED, NOT_RUN, SKIPPED, STOPPED, RunOutcome
from nmsm.batch.sweep import RunPlan, check_runs, expand, load_settings
from nmsm.batch.task import EVENT_TOPIC, owns_folder, read_record, recover, run_one
from nmsm.errors import InputError

#: times the scheduler of the built-in cluster runs a run again after its worker died
RETRIES = 1
#: Dask settings of the built-in cluster (scheduler, nannies and workers): each CPU-second its
#: processes spend on their own bookkeeping is taken from the solves when every core runs one.
#: A run goes to a worker once that worker is free (none waits in a busy worker's queue while
#: another idles); no statistical profiler sampling the running solve; event-loop health
#: checks and the nannies' memory checks once a second.
LOCAL_CLUSTER_CONFIG = {
    "distributed.scheduler.worker-saturation": 1.0,
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "1s",
}
#: seconds to wait for a scheduler given with ``scheduler=`` (``--scheduler``)
SCHEDULER_TIMEOUT = 10.0
#: seconds between looks at the runs while waiting
POLL = 0.2
#: part of every run's input digest; a change redoes every run
DIGEST_VERSION = "nmsm-batch-1"
BATCH_COPY = "batch.xml"
PLOTS = "plots"


@attrs.frozen
class BatchRun:
    """A finished (or stopped) batch: every run's outcome, the summary file, the figures."""

    spec: BatchSpec
    plans: tuple[RunPlan, ...]
    outcomes: dict[str, RunOutcome]
    summary_file: Path
    figures: tuple[Path, ...]
    wall_time: float  #: s, from the first check of a run to the last outcome (the cluster's start included)
    workers: int
    dashboard: str | None
    startup_time: float = 0.0  #: s, starting or connecting to the cluster (0: no run needed a worker)

    def count(self, status: str) -> int:
        return sum(o.status == status for o in self.outcomes.values())

    @property
    def ok(self) -> bool:
        return all(o.status in FINISHED for o in self.outcomes.values())

    def text(self) -> str:
        counts = ", ".join(f"{self.count(s)} {s}" for s in ("ok", SKIPPED, FAILED, NOT_RUN, STOPPED) if self.count(s))
        where = f"on {self.workers} worker(s)" if self.workers else "(no run needed a worker)"
        lines = [f"batch '{self.spec.name}': {len(self.plans)} runs ({counts}) in {self.wall_time:.1f} s {where}"]
        for plan in self.plans:
            outcome = self.outcomes[plan.name]
            if outcome.status not in FINISHED:
                lines.append(f"  {plan.name}: {outcome.status}: {outcome.message}")
        lines.append(f"summary: {self.summary_file}")
        return "\n".join(lines)


def input_digest(plan: RunPlan, cache: Any) -> str | None:
    """Digest of a settings run's inputs (settings with every path replaced by the digest of
    what it names, nmsm's code); None for a pipeline run (its runner keeps its stages up to
    date: :func:`_pipeline_up_to_date`)."""
    from nmsm.tools.pipeline.hashing import code_digest

    if plan.kind != "settings":
        return None
    kind, settings = load_settings(plan)
    return settings.input_digest(cache, kind.code, DIGEST_VERSION, code_digest())


def _pipeline_up_to_date(plan: RunPlan) -> bool:
    """Whether the pipeline runner finds every stage of a pipeline run up to date (checked
    without running anything; any problem: not up to date, the run reports it)."""
    from nmsm.tools.pipeline.pipeline_file import read_pipeline
    from nmsm.tools.pipeline.runner import DISABLED, UP_TO_DATE, run_pipeline

    if not (plan.folder / "pipeline_state.json").is_file():
        return False
    try:
        with warnings.catch_warnings():  # the run repeats them when it runs
            warnings.simplefilter("ignore")
            spec = attrs.evolve(read_pipeline(plan.source), results_directory=plan.folder)
            check = run_pipeline(spec, check_only=True, log=None)
    except Exception:  # noqa: BLE001 - the run itself reports what is wrong
        return False
    return all(stage.status in (UP_TO_DATE, DISABLED) for stage in check.stages)


def _finished_earlier(plan: RunPlan, digest: str | None, cache: Any) -> RunOutcome | None:
    """The recorded outcome (status ``skipped``) when the run finished with these inputs and its
    results are unchanged (a pipeline run: its runner finds every stage up to date), else None."""
    record = read_record(plan)
    if record is None or not plan.folder.is_dir() or record.get("outcome", {}).get("status") not in FINISHED:
        return None
    if plan.kind == "pipeline":
        if not _pipeline_up_to_date(plan):
            return None
    elif record.get("input_digest") != digest or cache.folder(plan.folder) != record.get("output_digest"):
        return None
    outcome = RunOutcome.from_json(record.get("outcome", {"name": plan.name, "status": SKIPPED}))
    return attrs.evolve(outcome, status=SKIPPED, message=f"finished {record.get('finished', 'earlier')} with the "
                                                           "same inputs")


def _check_folders(spec: BatchSpec, plans: list[RunPlan]) -> None:
    """Refuse a run's results folder or settings copy the batch did not write (never emptied)."""
    for plan in plans:
        folder = plan.folder
        if folder.exists() and (not folder.is_dir() or any(folder.iterdir())) and not owns_folder(plan):
            if plan.kind == "pipeline" and (folder / "pipeline_state.json").is_file():
                continue
            raise spec.error(f"the results folder {folder} of run '{plan.name}' exists and was not written by this "
                             "batch; nmsm replaces only results it wrote", element="<results_directory>",
                             expected=f"{folder} moved away or deleted by hand, or another results folder")
        copy = plan.settings_copy
        if plan.kind == "settings" and copy.exists() and not owns_folder(plan):
            raise spec.error(f"the settings copy {copy} of run '{plan.name}' exists and was not written by this "
                             "batch", element="<results_directory>",
                             expected=f"{copy} moved away, or another results folder")


@contextlib.contextmanager
def connect(workers: int | None, scheduler: str | None, timeout: float) -> Iterator[tuple[Any, int, str | None, bool]]:
    """``(client, number of workers, dashboard address or None, local)`` (module docstring, step 2)."""
    import dask
    from distributed import Client, LocalCluster

    from nmsm.core.threads import THREADS_VARIABLE

    if scheduler:
        try:
            client = Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"the scheduler at {scheduler} did not answer within {timeout:g} s ({exc})",
                             element="--scheduler",
                             expected="the address of a running Dask scheduler, e.g. tcp://host:8786") from None
        try:
            count = len(client.scheduler_info().get("workers", {}))
            dashboard = client.dashboard_link if "dashboard" in client.scheduler_info().get("services", {}) else None
            yield client, count, dashboard, False
        finally:
            client.close(timeout=timeout)
        return
    count = workers or os.cpu_count() or 1
    dashboard_wanted = importlib.util.find_spec("bokeh") is not None
    with dask.config.set(LOCAL_CLUSTER_CONFIG):  # read when each process starts (the nannies pass it on)
        cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=True, silence_logs=logging.ERROR,
                               dashboard_address=":0", env={THREADS_VARIABLE: "1"},
                               scheduler_kwargs={"allowed_failures": RETRIES, "dashboard": dashboard_wanted})
    try:
        with dask.config.set(LOCAL_CLUSTER_CONFIG):
            client = Client(cluster, timeout=timeout)
        try:
            yield client, count, cluster.dashboard_link if dashboard_wanted else None, True
        finally:
            client.close()
    finally:
        cluster.close()


class _Progress:
    """Console lines: each run's start and end with the counts of runs done, running, failed."""

    def __init__(self, total: int, log: Callable[[str], None]) -> None:
        self.total, self.log = total, log
        self.running: set[str] = set()
        self.done = self.failed = 0

    def started(self, name: str, worker: str) -> None:
        self.running.add(name)
        self.log(f"{self._counts()} {name}: started on {worker}")

    def finished(self, outcome: RunOutcome) -> None:
        self.running.discard(outcome.name)
        self.done += 1
        self.failed += outcome.status not in FINISHED
        detail = outcome.message if outcome.status not in FINISHED else ""
        if outcome.status == "ok":
            parts = [f"{outcome.wall_time:.1f} s" if outcome.wall_time is not None else "",
                     f"on {outcome.worker}" if outcome.worker else "",
                     f"objective {outcome.objective:.6g}" if outcome.objective is not None else "",
                     "second attempt (a worker died)" if outcome.attempts > 1 else ""]
            detail = ", ".join(p for p in parts if p)
        self.log(f"{self._counts()} {outcome.name}: {outcome.status}" + (f": {detail}" if detail else ""))
        for warning in outcome.warnings:
            self.log(f"    warning: {warning}")

    def _counts(self) -> str:
        return f"[{self.done}/{self.total} done, {len(self.running)} running, {self.failed} failed]"


def _collect(future: Any, plan: RunPlan) -> RunOutcome:
    """The outcome of a finished future (a worker that died twice: failed, with the reason)."""
    from distributed import KilledWorker

    try:
        return future.result()
    except KilledWorker as exc:
        return RunOutcome(plan.name, FAILED, attempts=RETRIES + 1,
                          message=f"the worker running it died in each of {RETRIES + 1} attempts (killed or out of "
                                  f"memory): {exc}")
    except Exception as exc:  # noqa: BLE001 - a run that could not be run is its outcome
        return RunOutcome(plan.name, FAILED, message=f"{type(exc).__name__}: {exc}")


class _Cluster:
    """The Dask client, connected at its first use (:func:`connect`), so that a rerun whose
    runs are all up to date starts no cluster; ``events``: the runs' "started" messages."""

    def __init__(self, workers: int | None, scheduler: str | None, timeout: float,
                 say: Callable[[str], None]) -> None:
        self.workers, self.scheduler, self.timeout, self.say = workers, scheduler, timeout, say
        self.stack = contextlib.ExitStack()
        self.client: Any = None
        self.count, self.dashboard = 0, None
        self.startup_time = 0.0
        self.events: queue.Queue = queue.Queue()

    def get(self) -> Any:
        if self.client is None:
            began = time.perf_counter()
            client, self.count, self.dashboard, _ = self.stack.enter_context(
                connect(self.workers, self.scheduler, self.timeout))
            self.startup_time = time.perf_counter() - began
            client.subscribe_topic(EVENT_TOPIC, lambda event: self.events.put(event[1]))
            self.say(f"{self.count} Dask worker(s)" + (f"; dashboard {self.dashboard}" if self.dashboard else ""))
            self.client = client
        return self.client


def _execute(cluster: _Cluster, plans: list[RunPlan], broken: dict[str, str], outcomes: dict[str, RunOutcome],
             futures: dict[Any, RunPlan], progress: _Progress,
             on_event: Callable[[str, str, dict[str, Any]], None] | None) -> None:
    """Run every plan (module docstring, step 3), filling ``outcomes``; ``futures`` holds the
    submitted ones not finished yet (for a stop)."""
    from distributed import wait
    from nmsm.tools.pipeline.hashing import DigestCache

    events = cluster.events
    cache = DigestCache(exclude=[plans[0].results_root] if plans else [])
    waiting = order(plans)

    def settle(outcome: RunOutcome) -> None:
        outcomes[outcome.name] = outcome
        progress.finished(outcome)
        if on_event is not None:
            on_event("finished", outcome.name, attrs.asdict(outcome))

    while waiting or futures:
        ready = True
        while ready:
            ready = False
            for plan in list(waiting):
                parents = [outcomes.get(d) for d in plan.depends_on]
                if any(p is None for p in parents):
                    continue
                waiting.remove(plan)
                ready = True
                if plan.name in broken:
                    settle(RunOutcome(plan.name, FAILED, message=broken[plan.name]))
                    continue
                unfinished = [(d, p) for d, p in zip(plan.depends_on, parents) if p.status not in FINISHED]
                if unfinished:
                    name, parent = unfinished[0]
                    settle(RunOutcome(plan.name, NOT_RUN, message=f"'{name}' did not finish ({parent.status})"))
                    continue
                try:
                    digest = input_digest(plan, cache)
                    earlier = _finished_earlier(plan, digest, cache)
                except Exception as exc:  # noqa: BLE001 - an input that cannot be hashed fails this run only
                    settle(RunOutcome(plan.name, FAILED, message=f"reading its inputs: {type(exc).__name__}: {exc}"))
                    continue
                if earlier is not None:
                    settle(earlier)
                    continue
                future = cluster.get().submit(run_one, plan, digest, pure=False,
                                              key=f"nmsm-batch-{plan.name}-{uuid.uuid4().hex[:8]}")
                futures[future] = plan
        if not futures:
            continue
        try:
            done, _ = wait(list(futures), timeout=POLL, return_when="FIRST_COMPLETED")
        except TimeoutError:
            done = set()
        for future in done:
            plan = futures.pop(future)
            settle(_collect(future, plan))
        while not events.empty():
            event = events.get()
            if event["run"] in outcomes:  # its end was seen first
                continue
            progress.started(event["run"], event["worker"])
            if on_event is not None:
                on_event("started", event["run"], dict(event))


def run_batch(batch_file: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
              workers: int | None = None, scheduler: str | None = None, timeout: float = SCHEDULER_TIMEOUT,
              log: Callable[[str], None] | None = print,
              on_event: Callable[[str, str, dict[str, Any]], None] | None = None) -> BatchRun:
    """Run a batch file (module docstring). ``log``: console lines (None: quiet);
    ``on_event(kind, run, details)``: called with ``"started"`` (details: worker, pid) and
    ``"finished"`` (details: the outcome's fields) for each run."""
    say = log or (lambda text: None)
    if workers is not None and workers < 1:
        raise InputError(f"{workers} workers", element="--workers", expected="a whole number >= 1")
    if workers is not None and scheduler:
        raise InputError("--workers sets the size of the local cluster; with --scheduler the cluster's own workers "
                         "run the batch", element="--workers", expected="--workers or --scheduler, not both")
    spec = read_batch(batch_file, results_directory)
    plans = link(spec, expand(spec))
    broken = check_runs(spec, plans)
    _check_folders(spec, plans)
    outcomes: dict[str, RunOutcome] = {}
    futures: dict[Any, RunPlan] = {}
    cluster = _Cluster(workers, scheduler, timeout, say)
    began: float | None = None
    try:
        with cluster.stack:
            if scheduler:  # an address that does not answer is refused before anything runs
                cluster.get()
            say(f"batch '{spec.name}': {len(plans)} runs, results in {spec.results_directory}")
            spec.results_directory.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(spec.file, spec.results_directory / BATCH_COPY)
            began = time.perf_counter()
            try:
                _execute(cluster, plans, broken, outcomes, futures, _Progress(len(plans), say), on_event)
            except BaseException:
                for future in futures:
                    future.cancel()
                raise
    except BaseException:
        if began is None:  # refused before any run started: nothing written
            raise
        if futures and not scheduler:  # the local workers are gone: put interrupted runs' earlier results back
            for plan in futures.values():
                recover(plan)
        for plan in plans:
            outcomes.setdefault(plan.name, RunOutcome(plan.name, STOPPED, message="the batch was stopped"))
        _write_outputs(spec, plans, outcomes)
        raise
    assert began is not None
    wall = time.perf_counter() - began
    summary, figures = _write_outputs(spec, plans, outcomes)
    outcomes = {plan.name: outcomes[plan.name] for plan in plans}  # the batch file's order
    return BatchRun(spec, tuple(plans), outcomes, summary, tuple(figures), wall, cluster.count, cluster.dashboard,
                    cluster.startup_time)


def _write_outputs(spec: BatchSpec, plans: list[RunPlan], outcomes: dict[str, RunOutcome]) -> tuple[Path, list[Path]]:
    """The summary, and the sweeps' figures drawn into a hidden folder and moved into ``plots/``."""
    import tempfile

    from nmsm.batch.summary import draw_sweeps, summary_rows, write_summary

    summary = write_summary(spec.results_directory, plans, outcomes)
    columns, rows = summary_rows(plans, outcomes)
    plots = spec.results_directory / PLOTS
    with tempfile.TemporaryDirectory(prefix=".nmsm-plots-", dir=spec.results_directory) as scratch:
        drawn = draw_sweeps(columns, rows, Path(scratch))
        if drawn:
            plots.mkdir(exist_ok=True)
        for path in drawn:
            os.replace(path, plots / path.name)
    return summary, [plots / p.name for p in drawn]

"""Benchmark: ``nmsm batch`` with 1 and 2 workers on the example's 10-variant DO sweep.

1. Generates the synthetic subject and ``nmsm example --batch``'s files
   (:func:`nmsm.examples.batch_example.write_example_batch`) and runs its pipeline up to the
   VO once (not timed; ``--keep DIR`` reuses a folder where it already ran);
2. writes ``sweep.xml``: the example's DO sweep alone (5 strengths x 2 synergy scalings),
   each variant starting from that VO (the DO file's own ``<initial_guess_directory>``);
3. runs the sweep ``--repeat`` times with 1 worker and with 2 workers, alternating, each
   into a fresh results folder, and prints per batch: the wall time from the cluster's start
   to the last result, the time to start the cluster, the sum of the runs' own
   wall times (measured inside each run on its worker), and the engine's overhead per run in
   the 1-worker batches, ``(wall - sum of run times) / runs`` (scheduling, serialization,
   hashing the inputs, moving results; a worker's first task also pays for importing nmsm);
   and the CPU seconds: each run's own (its worker process's CPU time while it ran, which
   the load of other processes hardly changes), this process's (client, scheduler and
   nannies: ``getrusage(RUSAGE_SELF)``) and the workers' in all (``RUSAGE_CHILDREN``, once
   the cluster has closed);
4. prints the medians and the speed-up ``median wall (1 worker) / median wall (2 workers)``,
   of the runs' schedule (the cluster's start to the last result) and of the whole call
   (``nmsm.batch.run``: starting the cluster, hashing the inputs, the summary and figures),
   and for each pair the speed-up and the cores the 2-worker batch got (its processes' CPU
   seconds over its whole call): below 2 while other processes took their share. On a
   machine whose scheduler groups processes by session (Linux autogroup, as on the shared
   CI machine), the batch's processes share one group's part of the cores whatever their
   number, so 2 workers gain nothing while other sessions keep the cores busy.

The VO every variant starts from is not part of the timed sweep: it is the parent run that
a batch holding both (``nmsm example --batch``) runs once and skips on every rerun; the
pipeline's own time is printed once, before the sweeps.

    python benchmarks/bench_batch.py [--repeat N] [--keep DIR]

Targets (issue #28): speed-up >= 1.8 on 2 cores, overhead <= 1 s a run. Prints the load
average with every batch: the machine is shared, so read the numbers beside it.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import tempfile
import time
from pathlib import Path


def _sweep_file(batch_folder: Path) -> Path:
    from nmsm.examples.batch_example import STRENGTHS, SYNERGY_SCALES, SWEEP, batch_xml

    text = batch_xml(STRENGTHS, SYNERGY_SCALES)
    start, end = text.index("      <Run "), text.index("      <Sweep ")
    text = text[:start] + text[end:]  # the sweep alone
    text = text.replace("        <warm_start_from>subject/vo</warm_start_from>\n", "")
    assert f'<Sweep name="{SWEEP}"' in text and "<Run " not in text and "warm_start_from" not in text
    path = batch_folder / "sweep.xml"
    path.write_text(text, encoding="utf-8")
    return path


def _one(sweep: Path, results: Path, workers: int) -> dict[str, float]:
    from nmsm.batch import run

    usage = [resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    began = time.perf_counter()
    outcome = run(sweep, results_directory=results, workers=workers, log=None)
    total = time.perf_counter() - began
    client, workers_cpu = (after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime for before, after in
                           zip(usage, [resource.getrusage(who) for who in (resource.RUSAGE_SELF,
                                                                           resource.RUSAGE_CHILDREN)]))
    if not outcome.ok:
        raise SystemExit(outcome.text())
    runs = [o.wall_time for o in outcome.outcomes.values()]
    cpu = [o.cpu_time for o in outcome.outcomes.values()]
    wall = outcome.wall_time - outcome.startup_time  # the runs' schedule, without starting the cluster
    figures = {"workers": workers, "wall": wall, "total": total, "startup": outcome.startup_time,
               "runs": sum(runs), "n": len(runs), "load": os.getloadavg()[0], "cpu_run": statistics.median(cpu),
               "cpu_runs": sum(cpu), "cpu_client": client, "cpu_workers": workers_cpu}
    figures["overhead"] = (wall - figures["runs"]) / len(runs)
    figures["cores"] = (client + workers_cpu) / total
    print(f"{workers} worker(s): wall {wall:.1f} s from the cluster's start to the last result (cluster start "
          f"{outcome.startup_time:.1f} s; the whole call {total:.1f} s), runs {figures['runs']:.1f} s in all "
          f"({figures['runs'] / len(runs):.1f} s each), overhead per run {figures['overhead']:.2f} s (meaningful "
          f"with 1 worker); CPU s: runs {sum(cpu):.1f} in all (median {figures['cpu_run']:.2f} a run, "
          f"{min(cpu):.2f}-{max(cpu):.2f}), workers {workers_cpu:.1f}, client+scheduler+nannies {client:.1f}, cores "
          f"used {figures['cores']:.2f} (CPU / whole call); load average {os.getloadavg()}", flush=True)
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=2, help="batches per worker count (default 2)")
    parser.add_argument("--keep", help="work in this folder and keep it (default: a temporary folder)")
    args = parser.parse_args(argv)
    from nmsm.examples.batch_example import write_example_batch
    from nmsm.tools.pipeline.runner import run_pipeline_file

    folder = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="nmsm_bench_batch_"))
    print(f"load average before: {os.getloadavg()}", flush=True)
    batch = write_example_batch(folder).parent
    began = time.perf_counter()
    run_pipeline_file(batch / "pipeline.xml", log=None)  # the VO every variant starts from
    print(f"pipeline up to the VO: {time.perf_counter() - began:.1f} s", flush=True)
    sweep = _sweep_file(batch)
    results: dict[int, list[dict[str, float]]] = {1: [], 2: []}
    for k in range(args.repeat):
        for workers in (1, 2):
            target = batch / f"bench_{workers}w_{k}"
            shutil.rmtree(target, ignore_errors=True)
            results[workers].append(_one(sweep, target, workers))
            shutil.rmtree(target, ignore_errors=True)
    for k, (one, two) in enumerate(zip(results[1], results[2])):
        print(f"pair {k + 1}: speed-up {one['wall'] / two['wall']:.2f}x (whole call "
              f"{one['total'] / two['total']:.2f}x), cores used with 2 workers {two['cores']:.2f}")
    wall = {w: statistics.median(r["wall"] for r in rows) for w, rows in results.items()}
    total = {w: statistics.median(r["total"] for r in rows) for w, rows in results.items()}
    cpu = {w: statistics.median(r["cpu_run"] for r in rows) for w, rows in results.items()}
    overhead = statistics.median(r["overhead"] for r in results[1])
    print(f"median wall: 1 worker {wall[1]:.1f} s, 2 workers {wall[2]:.1f} s; speed-up {wall[1] / wall[2]:.2f}x "
          f"(target >= 1.8); engine overhead per run (1 worker) {overhead:.2f} s (target <= 1 s)")
    print(f"median whole call: 1 worker {total[1]:.1f} s, 2 workers {total[2]:.1f} s; speed-up "
          f"{total[1] / total[2]:.2f}x")
    print(f"median CPU s a run: 1 worker {cpu[1]:.2f}, 2 workers {cpu[2]:.2f}")
    print(f"load average after: {os.getloadavg()}")
    if not args.keep:
        shutil.rmtree(folder, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Treatment Optimization at full-body scale: build time, time per iteration, memory (issue 24).

Runs a TO settings file the way ``nmsm run`` does (:func:`nmsm.tools.treatment.run.run_settings`,
results written) in a child process and prints, next to the issue's targets and the
published references:

* NLP build: reading and building the problem (``prepare``) and constructing the solver
  (CasADi's derivative functions, ``nlpsol``), CPU and wall seconds;
* per IPOPT iteration: CPU seconds in CasADi's function and derivative evaluations and in
  IPOPT itself (the linear solves), from IPOPT's timing statistics;
* iterations, IPOPT's status, wall time from the call to written results, peak resident memory.

The case: ``--settings FILE`` (e.g. the full-body stress case), or by default the synthetic
case of ``benchmarks/scale_case.py`` (31 states, 86 muscles in 5 + 5 synergies with the
vectors optimized, 25 x 4 points; synthetic geometry and neural data, see there).
``--curves`` instead measures build, one evaluation of each derivative and memory over
nodes and muscles (a few iterations each) and writes ``docs/treatment_scale.png`` and the
numbers as JSON. Run one at a time, under a memory limit (the machine is shared)::

    (ulimit -v 14000000; python benchmarks/bench_treatment_scale.py [--settings F] [--max-iterations N])
    (ulimit -v 14000000; python benchmarks/bench_treatment_scale.py --curves)

Give ``cat /proc/loadavg`` with the numbers (printed at start and end).
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import re
import resource
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

#: the issue's targets (2 cores) and published references
TARGETS = {"run": 600.0, "build": 60.0, "memory_gb": 4.0}
REFERENCES = (
    "original NMSM Pipeline TO (full body, 86 muscles, GPOPS-II): 770 CPU-minutes on 48 cores",
    "OpenSim Moco MocoTrack, 3D 29 coordinates, 80 muscles: 101-148 min on 8 threads (Dembia et al. 2020)",
    "PredSim 3D predictive gait with AD: 20-36 min (Falisse et al. 2019)",
)


def _loadavg() -> str:
    return " ".join(Path("/proc/loadavg").read_text().split()[:3])


def _timing(log: str) -> dict[str, float]:
    """CPU seconds of IPOPT's timing statistics (function evaluations by kind, linear solves)."""
    out = {}
    for key, label in (("functions", r"Function Evaluations"), ("hessian", r"Lagrangian Hessian"),
                       ("jacobian_eq", r"Equality constraint Jacobian"),
                       ("jacobian_ineq", r"Inequality constraint Jacobian"),
                       ("linear", r"PDSystemSolverTotal"), ("total", r"OverallAlgorithm")):
        m = re.search(label + r"\.*:\s*([0-9.]+) \(sys:\s*[0-9.]+ wall:\s*([0-9.]+)\)", log)
        if m:
            out[key] = float(m.group(1))
            out[key + "_wall"] = float(m.group(2))
    return out


def _worker(settings: str, results: str, max_iterations: int | None, queue: Any) -> None:
    import warnings

    import casadi as cs

    import nmsm.core.backends.ipopt as backend
    from nmsm.errors import SolverError
    from nmsm.tools.treatment.run import run_settings

    warnings.simplefilter("ignore")
    record: dict[str, Any] = {}
    original = backend.cs.nlpsol

    def timed(*args: Any, **kwargs: Any) -> Any:
        cpu, wall = time.process_time(), time.perf_counter()
        solver = original(*args, **kwargs)
        record["nlpsol_cpu"], record["nlpsol_wall"] = time.process_time() - cpu, time.perf_counter() - wall
        record["nlpsol_rss_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
        return solver

    backend.cs.nlpsol = timed
    import nmsm.tools.treatment.run as run_module

    prepare = run_module.prepare

    def timed_prepare(*args: Any, **kwargs: Any) -> Any:
        cpu, wall = time.process_time(), time.perf_counter()
        prepared = prepare(*args, **kwargs)
        record["prepare_cpu"], record["build_wall"] = time.process_time() - cpu, time.perf_counter() - wall
        record["n_variables"] = prepared.built.problem.n_variables
        return prepared

    run_module.prepare = timed_prepare
    cpu, wall = time.process_time(), time.perf_counter()
    options: dict[str, Any] = {"results_directory": results, "print_level": 0,
                               "ipopt_options": {"print_timing_statistics": "yes"}}
    if max_iterations:
        options["max_iterations"] = max_iterations
    try:
        run = run_settings(settings, **options)
        record.update(status=run.solution.status, iterations=run.solution.iterations)
        folder = Path(results)
    except SolverError as exc:
        record.update(status=f"not converged: {exc}".splitlines()[0][:200])
        folder = Path(results) / "last_iterate"
    except Exception as exc:  # noqa: BLE001 - reported to the parent, which would wait forever
        record.update(status=f"error: {type(exc).__name__}: {exc}"[:300], run_cpu=0.0, run_wall=0.0,
                      peak_rss_gb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6)
        queue.put(record)
        return
    record["run_cpu"], record["run_wall"] = time.process_time() - cpu, time.perf_counter() - wall
    logs = sorted(folder.rglob("*_ipopt.log"))
    if logs:
        text = logs[0].read_text()
        record["timing"] = _timing(text)
        m = re.search(r"Number of Iterations\.*:\s*(\d+)", text)
        if m:
            record["iterations"] = int(m.group(1))
    record["casadi_version"] = cs.__version__
    record["peak_rss_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
    queue.put(record)


def measure(settings: Path, max_iterations: int | None = None) -> dict[str, Any]:
    """Run ``settings`` in a child process; its numbers and peak resident memory (GB)."""
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    with tempfile.TemporaryDirectory(prefix="nmsm-scale-") as results:
        process = ctx.Process(target=_worker, args=(str(settings), results, max_iterations, queue))
        process.start()
        record = queue.get()
        process.join()
    return record


def report(record: dict[str, Any]) -> str:
    t = record.get("timing", {})
    iters = max(int(record.get("iterations") or 0), 1)
    build = record.get("nlpsol_wall", 0.0) + record.get("build_wall", 0.0)
    lines = [
        f"{'quantity':<52s} {'measured':>12s} {'target':>10s}",
        f"{'NLP build: prepare + nlpsol, wall s':<52s} {build:12.1f} {TARGETS['build']:10.0f}",
        f"{'  prepare CPU s':<52s} {record.get('prepare_cpu', float('nan')):12.1f}",
        f"{'  nlpsol (derivatives) CPU s':<52s} {record.get('nlpsol_cpu', float('nan')):12.1f}",
        f"{'nmsm run -> written results, wall s':<52s} {record['run_wall']:12.1f} {TARGETS['run']:10.0f}",
        f"{'  CPU s':<52s} {record['run_cpu']:12.1f}",
        f"{'peak resident memory, GB':<52s} {record['peak_rss_gb']:12.2f} {TARGETS['memory_gb']:10.1f}",
        f"{'IPOPT iterations':<52s} {record.get('iterations', -1):12d}",
        f"{'per iteration: function + derivative evaluations CPU s':<52s} {t.get('functions', 0) / iters:12.3f}",
        f"{'  of which Lagrangian Hessian CPU s':<52s} {t.get('hessian', 0) / iters:12.3f}",
        f"{'  of which constraint Jacobians CPU s':<52s} "
        f"{(t.get('jacobian_eq', 0) + t.get('jacobian_ineq', 0)) / iters:12.3f}",
        f"{'per iteration: linear solves (IPOPT) CPU s':<52s} {t.get('linear', 0) / iters:12.3f}",
        f"status: {str(record.get('status'))[:120]}; variables {record.get('n_variables', '?')}; "
        f"CasADi {record.get('casadi_version')}",
        "references:",
        *[f"  {r}" for r in REFERENCES],
    ]
    return "\n".join(lines)


#: sizes of the curves: (intervals, points, muscles per leg)
NODE_SIZES = ((5, 4, 43), (10, 4, 43), (25, 4, 43))
MUSCLE_SIZES = ((5, 4, 0), (5, 4, 10), (5, 4, 20), (5, 4, 43))


def curves(out: Path, iterations: int) -> dict[str, Any]:
    from scale_case import write_case

    rows = []
    with tempfile.TemporaryDirectory(prefix="nmsm-scale-case-") as scratch:
        for intervals, points, muscles in sorted(dict.fromkeys(NODE_SIZES + MUSCLE_SIZES)):
            settings = write_case(Path(scratch) / f"{intervals}x{points}_{muscles}", intervals=intervals,
                                  points=points, muscles_per_leg=muscles)
            record = measure(settings, iterations)
            record.update(points=intervals * points, muscles=2 * muscles, loadavg=_loadavg())
            print(json.dumps({k: v for k, v in record.items() if k != "timing"}), flush=True)
            rows.append(record)
            (out / "treatment_scale.json").write_text(json.dumps(rows, indent=1))
    _plot(rows, out / "treatment_scale.png")
    return {"rows": rows}


def _plot(rows: list[dict[str, Any]], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for key, sizes, label in (("points", NODE_SIZES, "collocation points (86 muscles)"),
                              ("muscles", MUSCLE_SIZES, "muscles (20 points)")):
        chosen = [r for r in rows if (r["points"] // 4, 4, r["muscles"] // 2) in
                  {(i, p, m) for i, p, m in sizes}]
        chosen.sort(key=lambda r: r[key])
        x = [r[key] for r in chosen]
        it = [max(int(r.get("iterations") or 1), 1) for r in chosen]
        axes[0].plot(x, [r.get("nlpsol_cpu", 0) for r in chosen], "o-", label=label)
        axes[1].plot(x, [r.get("timing", {}).get("functions", 0) / n for r, n in zip(chosen, it)], "o-", label=label)
        axes[2].plot(x, [r["peak_rss_gb"] for r in chosen], "o-", label=label)
    for ax, title in zip(axes, ("solver construction (derivatives), CPU s", "evaluations per iteration, CPU s",
                                "peak resident memory, GB")):
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("collocation points or muscles")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Treatment Optimization growth (synthetic full-body case, 31 states; benchmarks/bench_treatment_scale.py)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--settings", type=Path, help="a TO settings file (default: the synthetic case)")
    parser.add_argument("--max-iterations", type=int, help="stop IPOPT after this many iterations")
    parser.add_argument("--curves", action="store_true", help="measure growth over nodes and muscles")
    parser.add_argument("--curve-iterations", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "docs")
    args = parser.parse_args(argv)
    print("load average", _loadavg(), flush=True)
    if args.curves:
        curves(args.out, args.curve_iterations)
    else:
        with tempfile.TemporaryDirectory(prefix="nmsm-scale-case-") as scratch:
            settings = args.settings
            if settings is None:
                from scale_case import write_case

                settings = write_case(Path(scratch) / "case")
            record = measure(settings, args.max_iterations)
        print(report(record))
    print("load average", _loadavg(), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

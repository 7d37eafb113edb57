"""The full-body gait case at clinical scale (issue 24): TO, VO and DO, measured.

    python benchmarks/bench_fullbody.py --folder DIR [--case stress] [--mesh full]
        [--tools to vo do] [--max-iterations N] [--memory-limit-gb 14] [--surrogate] [--json FILE]
        [--start-from-coarse]

Prepares ``DIR`` with :func:`nmsm.examples.fullbody.write_case` (inputs reused when present),
then runs each tool's settings file in a child process (address space capped at
``--memory-limit-gb``, so a run that would swap fails instead) with IPOPT's timing statistics,
and prints per tool: NLP build time (s, from reading the settings to IPOPT's start),
iterations, wall time of the solve, time per iteration split into function/derivative
evaluation and the rest (linear solves and IPOPT's own work), peak resident memory of the
child (GB, ``ru_maxrss``) and the load average before and after, next to the issue's targets
and the published references. ``--surrogate`` also times surrogate sampling and fitting for
the 86 muscles x 14 coordinates (``nmsm surrogate --motion ... --write-samples``).
``--start-from-coarse`` (full mesh): first solves the TO on the coarse mesh and starts the
full mesh's TO from its results (``nmsm run ... --start-from``), and prints the two together.

Only one stress run at a time: its TO has held 12 GB.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

TARGETS = {"to": ("TO from nmsm run to written results", 600.0), "vo": ("VO", 300.0), "do": ("DO", 300.0),
           "to_coarse": ("coarse-mesh TO that starts the full mesh's", 600.0)}
BUILD_TARGET_S = 60.0
MEMORY_TARGET_GB = 4.0
SURROGATE_TARGET_S = 60.0
REFERENCES = (
    "original NMSM Pipeline (MATLAB, GPOPS-II): full-body synergy TO 770 CPU-minutes on 48 cores",
    "OpenSim Moco MocoTrack, 3D 29-coordinate 80-muscle gait: 101-148 min on 8 threads (Dembia et al. 2020)",
    "PredSim 3D predictive gait with AD: 20-36 min (Falisse et al. 2019)",
)

CHILD = r"""
import json, sys, time, resource
from nmsm.tools.treatment.run import run_settings
options = json.loads(sys.argv[2])
start = time.perf_counter()
row = {}
try:
    run = run_settings(sys.argv[1], **options)
    s = run.solution
    row = dict(success=bool(s.success), status=s.status, iterations=int(s.iterations), solve_s=float(s.wall_time),
               build_s=float(run.build_time), cost=float(s.cost), variables=int(s.x_scaled.size),
               results=str(run.results_directory))
except BaseException as exc:
    row = dict(success=False, status=f"{type(exc).__name__}: {str(exc)[:400]}")
row["total_s"] = time.perf_counter() - start
row["peak_rss_gb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024 ** 2
print("BENCH_ROW " + json.dumps(row), flush=True)
"""

#: IPOPT timing-statistics lines (wall seconds) that are function or derivative evaluations
EVALUATIONS = ("Objective function", "Objective function gradient", "Equality constraints",
               "Inequality constraints", "Equality constraint Jacobian", "Inequality constraint Jacobian",
               "Lagrangian Hessian")


def load_average() -> str:
    """The 1, 5 and 15 minute load averages."""
    return " ".join(Path("/proc/loadavg").read_text().split()[:3]) if Path("/proc/loadavg").exists() else "?"


def _limit(gigabytes: float):
    def apply() -> None:
        limit = int(gigabytes * 1024 ** 3)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    return apply


TIMING_LINE = re.compile(r"\s*([A-Za-z][A-Za-z \-]+?)\s*\.+:\s*([\d.eE+-]+)\s*"
                         r"\(sys:\s*[\d.eE+-]+\s*wall:\s*([\d.eE+-]+)\)")


def ipopt_timing(text: str) -> dict[str, float]:
    """Wall seconds of IPOPT's ``print_timing_statistics`` lines (``name....: cpu wall``)."""
    out = {}
    for line in text.splitlines():
        m = TIMING_LINE.match(line)
        if m:
            out[m.group(1).strip()] = float(m.group(3))
    return out


def run_tool(settings: Path, tool: str, memory_gb: float, max_iterations: int | None, log: Path,
             start_from: Path | None = None) -> dict:
    options = {"ipopt_options": {"print_timing_statistics": "yes"}}
    if max_iterations is not None:
        options["max_iterations"] = max_iterations
    if start_from is not None:
        options["guess_directory"] = str(start_from)
    before = load_average()
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with open(log, "w", encoding="utf-8") as out:
        proc = subprocess.run([sys.executable, "-c", CHILD, str(settings), json.dumps(options)], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, env=env, preexec_fn=_limit(memory_gb), check=False)
        out.write(proc.stdout)
    rows = [json.loads(line.split(" ", 1)[1]) for line in proc.stdout.splitlines() if line.startswith("BENCH_ROW ")]
    row = rows[-1] if rows else {"success": False, "status": f"child exited {proc.returncode} (see {log})"}
    timing = ipopt_timing(proc.stdout)
    evaluation = sum(v for k, v in timing.items() if k in EVALUATIONS)
    row.update(tool=tool, settings=str(settings), load_before=before, load_after=load_average(), log=str(log),
               evaluation_s=evaluation if timing else None, ipopt_s=timing.get("OverallAlgorithm"))
    return row


def time_surrogate(folder: Path, memory_gb: float) -> dict:
    from nmsm.examples import fullbody_data as fd

    out = folder / "bench_surrogate"
    if out.exists():
        import shutil

        shutil.rmtree(out)
    out.mkdir()
    before = load_average()
    start = time.perf_counter()
    model = folder / "model" / "fullbody.osim"
    proc = subprocess.run([sys.executable, "-m", "nmsm", "surrogate", "--model", str(model),
                           "--motion", str(folder / "data" / "IKData" / f"{fd.TRIAL}.sto"), "--coordinates",
                           *fd.muscle_coordinates(), "--write-samples", str(out / "samples"), "-o",
                           str(out / "surrogate.json")], capture_output=True, text=True, preexec_fn=_limit(memory_gb),
                          check=False)
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return dict(tool="surrogate", success=proc.returncode == 0, total_s=time.perf_counter() - start,
                cpu_s=usage.ru_utime + usage.ru_stime, load_before=before, load_after=load_average())


def print_rows(rows: list[dict]) -> None:
    print("\n| tool | status | variables | build s | iterations | solve s | s / iteration | evaluation s / it "
          "| other s / it | total s (target) | peak GB (target 4) | load before / after |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r["tool"] == "surrogate":
            print(f"| surrogate 86 x 14 | {'ok' if r['success'] else 'FAILED'} | | | | | | | | "
                  f"{r['total_s']:.1f} ({SURROGATE_TARGET_S:g}) | | {r['load_before']} / {r['load_after']} |")
            continue
        it = r.get("iterations") or 0
        per = r["solve_s"] / it if it else float("nan")
        ev = r.get("evaluation_s")
        ev_it = ev / it if (ev is not None and it) else float("nan")
        other = per - ev_it if it else float("nan")
        target = TARGETS[r["tool"]][1]
        print(f"| {r['tool'].upper()} | {r['status'][:60]} | {r.get('variables', '')} | "
              f"{r.get('build_s', float('nan')):.1f} ({BUILD_TARGET_S:g}) | {it} | "
              f"{r.get('solve_s', float('nan')):.1f} | "
              f"{per:.2f} | {ev_it:.2f} | {other:.2f} | {r['total_s']:.1f} ({target:g}) | "
              f"{r.get('peak_rss_gb', float('nan')):.2f} | {r['load_before']} / {r['load_after']} |")
    coarse = [r for r in rows if r["tool"] == "to_coarse"]
    full = [r for r in rows if r["tool"] == "to"]
    if coarse and full:
        total = coarse[0]["total_s"] + full[0]["total_s"]
        print(f"\nTO, coarse then full mesh: {total:.1f} s (target {TARGETS['to'][1]:g})")
    print("\nreferences:")
    for ref in REFERENCES:
        print(f"  {ref}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--folder", default=None, help="case folder (default: a new temporary folder)")
    parser.add_argument("--case", default="stress", choices=("stress", "combined"))
    parser.add_argument("--mesh", default="full", choices=("full", "coarse"))
    parser.add_argument("--tools", nargs="+", default=["to", "vo", "do"], choices=("to", "vo", "do"))
    parser.add_argument("--max-iterations", type=int, default=None)
    parser.add_argument("--memory-limit-gb", type=float, default=14.0)
    parser.add_argument("--surrogate", action="store_true", help="also time surrogate sampling + fit (86 x 14)")
    parser.add_argument("--json", default=None)
    parser.add_argument("--start-from-coarse", action="store_true",
                        help="full mesh: start the TO from the same case's TO solved on the coarse mesh")
    args = parser.parse_args()
    folder = Path(args.folder) if args.folder else Path(tempfile.mkdtemp(prefix="bench_fullbody_"))
    from nmsm.examples.fullbody import write_case

    start = time.perf_counter()
    paths = write_case(folder, args.case, args.mesh)
    print(f"case prepared in {time.perf_counter() - start:.1f} s: {folder} (load {load_average()})", flush=True)
    rows = []
    if args.surrogate:
        rows.append(time_surrogate(folder, args.memory_limit_gb))
    start_from = None
    if args.start_from_coarse and args.mesh == "full" and "to" in args.tools:
        coarse = write_case(folder, args.case, "coarse")
        row = run_tool(coarse["to"], "to_coarse", args.memory_limit_gb, args.max_iterations,
                       folder / f"bench_{args.case}_coarse_to.log")
        rows.append(row)
        print(json.dumps(row), flush=True)
        if not row["success"]:
            print_rows(rows)
            return 0
        start_from = Path(row["results"])
    for tool in args.tools:
        row = run_tool(paths[tool], tool, args.memory_limit_gb, args.max_iterations,
                       folder / f"bench_{args.case}_{args.mesh}_{tool}.log", start_from if tool == "to" else None)
        rows.append(row)
        print(json.dumps(row), flush=True)
        if not row["success"]:
            break
    print_rows(rows)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""nmsm vs OpenSim Moco on the Moco 2D gait tracking problem, run back to back.

For each mode (torque-driven, muscle-driven) it writes the problem
(:func:`nmsm.examples.moco2d.write_problem`), solves it with nmsm (``run_settings``, IPOPT
with exact derivatives), then solves the anchors' MocoTrack problem in the OpenSim worker
(bridge command ``moco_track_2d``: same model, reference, 50 mesh intervals, tolerance
1e-4, the anchors' weights), and prints wall time, iterations, objective (Moco's units) and
the final tracking errors of both against the tracked reference (Moco's 6 Hz low-pass
filtered ``referenceCoordinates.sto``, which both track; coordinates RMS in deg, pelvis
translations in mm; ``referenceGRF.sto`` for the GRF, in N), with ``uptime`` before and after each solve (the
machine is shared: only ratios measured together count).

    /tmp/dev/bin/python benchmarks/bench_moco2d.py [--modes torque muscle] [--which both]
        [--mesh 50] [--points 2] [--tolerance 1e-4] [--like-moco] [--work DIR] [--json FILE]

``--like-moco``: our problem as Moco's (``write_problem(like_moco=True)``): muscle mode with
excitations as controls and DeGrooteFregly2016 activation dynamics, activations periodic
r<->l; control periodicity (lumbar; torque mode: joint torques r<->l).

Nothing is written into the data folder; everything goes to ``--work`` (default: a new
temporary folder). ``--json`` saves the rows; ``--table FILE...`` only prints saved rows.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import tempfile
import time
import warnings
from pathlib import Path

DATA = Path(os.environ.get("NMSM_SHARED_DATA", "/work/shared/data")) / "moco2d"


def uptime() -> str:
    try:
        return subprocess.run(["uptime"], capture_output=True, text=True, check=False).stdout.strip()
    except OSError:
        return "(uptime unavailable)"


def reference() -> object:
    """Moco's tracked reference (6 Hz low-pass of referenceCoordinates.sto, by OpenSim)."""
    from nmsm.examples.moco2d import states_reference_table
    from nmsm.opensim_bridge.client import get_bridge

    return states_reference_table(get_bridge(), DATA)


def run_ours(work: Path, mode: str, mesh: int, points: int, tolerance: float, like_moco: bool = False) -> dict:
    from nmsm.examples.moco2d import read_solution, tracking_error, write_problem
    from nmsm.tools.treatment.run import run_settings

    ref = reference()
    problem = write_problem(work / f"nmsm_{mode}{'_like_moco' if like_moco else ''}", DATA, mode,
                            mesh_intervals=mesh, points_per_interval=points, tolerance=tolerance, reference=ref,
                            like_moco=like_moco)
    load_before = uptime()
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_settings(problem.settings, results_directory=problem.results,
                           objective_scaling=problem.objective_factor, ipopt_options={"constr_viol_tol": tolerance})
    wall = time.perf_counter() - t0
    t, q, grf = read_solution(problem.results)
    err = tracking_error(DATA, t, q, grf, ref)
    return dict(solver="nmsm" + (" (like Moco)" if like_moco else ""), mode=mode, wall_s=wall, solve_s=run.solution.wall_time, build_s=run.build_time,
                iterations=run.solution.iterations, objective=run.cost * problem.objective_factor,
                success=bool(run.solution.success), status=run.solution.status,
                coordinates_deg=err.coordinates_deg, translations_mm=err.translations_mm, grf_n=err.grf_n,
                load_before=load_before, load_after=uptime())


def run_moco(work: Path, mode: str, mesh: int, tolerance: float, parallel: int) -> dict:
    from nmsm.examples.moco2d import COORDINATES, GRF_COLUMNS, tracking_error
    from nmsm.opensim_bridge.client import get_bridge

    bridge = get_bridge()
    load_before = uptime()
    t0 = time.perf_counter()
    r = bridge.call("moco_track_2d", model_file=str(DATA / "2D_gait.osim"),
                    coordinates_file=str(DATA / "referenceCoordinates.sto"), grf_file=str(DATA / "referenceGRF.sto"),
                    workdir=str(work / f"moco_{mode}"), mode=mode, mesh_intervals=mesh, tolerance=tolerance,
                    parallel=parallel)
    wall = time.perf_counter() - t0
    q = {c: r["q"][:, r["coordinates"].index(c)] for c in COORDINATES}
    grf = {c: r["grf"][:, r["grf_labels"].index(c)] for c in GRF_COLUMNS}
    err = tracking_error(DATA, r["time"], q, grf, reference())
    return dict(solver="Moco", mode=mode, wall_s=r["setup_s"] + r["wall_s"], solve_s=r["wall_s"],
                build_s=r["setup_s"], call_s=wall, iterations=r["iterations"], objective=r["objective"],
                success=r["success"], status=r["status"], objective_terms=r["objective_terms"],
                coordinates_deg=err.coordinates_deg, translations_mm=err.translations_mm, grf_n=err.grf_n,
                load_before=load_before, load_after=uptime())


def table(rows: list[dict]) -> str:
    lines = ["| mode | solver | wall s (setup + solve) | solve s | iterations | objective (Moco units) | status | "
             "coord RMS deg | pelvis tx/ty RMS mm | GRF RMS N | speed-up |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    by_mode: dict[str, dict[str, dict]] = {}
    for r in rows:
        by_mode.setdefault(r["mode"], {})[r["solver"]] = r
    for r in rows:
        pair = by_mode[r["mode"]]
        speed = ""
        if r["solver"].startswith("nmsm") and "Moco" in pair:
            speed = f"{pair['Moco']['wall_s'] / r['wall_s']:.1f}x"
        lines.append(f"| {r['mode']} | {r['solver']} | {r['wall_s']:.1f} | {r['solve_s']:.1f} | {r['iterations']} | "
                     f"{r['objective']:.4f} | {r['status']} | {r['coordinates_deg']:.3f} | "
                     f"{r['translations_mm']:.2f} | {r['grf_n']:.1f} | {speed} |")
    lines.append("")
    for r in rows:
        lines.append(f"- {r['mode']} {r['solver']}: load before `{r['load_before']}`, after `{r['load_after']}`")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--modes", nargs="+", default=["torque", "muscle"], choices=["torque", "muscle"])
    ap.add_argument("--which", default="both", choices=["both", "ours", "moco"])
    ap.add_argument("--mesh", type=int, default=50)
    ap.add_argument("--points", type=int, default=2, help="nmsm Radau collocation points per mesh interval")
    ap.add_argument("--tolerance", type=float, default=1e-4)
    ap.add_argument("--parallel", type=int, default=2, help="Moco's parallel threads (the anchors used 2)")
    ap.add_argument("--like-moco", action="store_true",
                    help="our problem with Moco's activation dynamics and control periodicity")
    ap.add_argument("--work", type=Path, default=None)
    ap.add_argument("--json", type=Path, default=None, help="save the rows here")
    ap.add_argument("--table", type=Path, nargs="+", default=None,
                    help="print the table of saved --json files (rows concatenated) and exit")
    a = ap.parse_args()
    if a.table is not None:
        print(table([row for path in a.table for row in json.loads(path.read_text())]))
        return
    work = a.work or Path(tempfile.mkdtemp(prefix="bench_moco2d_"))
    work.mkdir(parents=True, exist_ok=True)
    print(f"work folder {work}; cores {os.cpu_count()}", flush=True)
    rows = []
    for mode in a.modes:
        if a.which in ("both", "ours"):
            rows.append(run_ours(work, mode, a.mesh, a.points, a.tolerance, a.like_moco))
            print(json.dumps(rows[-1]), flush=True)
        if a.which in ("both", "moco"):
            rows.append(run_moco(work, mode, a.mesh, a.tolerance, a.parallel))
            print(json.dumps(rows[-1]), flush=True)
        if a.json is not None:
            a.json.write_text(json.dumps(rows, indent=1))
    print()
    print(table(rows))


if __name__ == "__main__":
    main()

"""Benchmark of Tracking / Verification / Design Optimization on the kicking tutorials.

For every settings file of ``treatment/torque_kick_tutorial`` and
``treatment/synergy_kick_tutorial`` (and the toy arm with ``--toy``):

1. *as given*: run the settings file unchanged (references from the folders it names: the
   original pipeline's results for VO/DO), record wall time, iterations, cost; score the
   original's solution in the same problem (``compare.score_solution``) and compare costs
   and tracking RMS. Free-final-time DO files are also run with
   ``rescale_prescribed_derivatives=False`` (the original's convention) for a like-for-like
   comparison.
2. *chained*: TO -> VO -> DO on our own results (VO V1/V2 from our TO V1 (torque) / V3
   (synergy); DO from our VO V2), timing each run and checking that VO reproduces TO
   (max joint angle and moment differences).

Run (2 cores, nothing else running for honest timings)::

    python benchmarks/bench_treatment.py --out /tmp/bench_treatment [--only torque|synergy] [--toy]

Writes ``results.json`` and ``results.md`` into ``--out``.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.tools.treatment.compare import Comparison, max_constraint_violation, score_solution, tracking_rms
from nmsm.tools.treatment.run import run_settings

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "treatment"

TORQUE = ["TorqueTOSettingsV1", "TorqueTOSettingsV2", "TorqueVOSettingsV1", "TorqueVOSettingsV2",
          "TorqueDOSettingsV1", "TorqueDOSettingsV2", "TorqueDOSettingsV3", "TorqueDOSettingsV4", "TorqueDOSettingsV5"]
SYNERGY = ["SynergyTOSettingsV1", "SynergyTOSettingsV2", "SynergyTOSettingsV3", "SynergyTOSettingsV4",
           "SynergyTOSettingsV5", "SynergyVOSettingsV1", "SynergyVOSettingsV2", "SynergyDOSettingsV1",
           "SynergyDOSettingsV2"]
FREE_TIME = {"TorqueDOSettingsV3", "TorqueDOSettingsV4", "SynergyDOSettingsV1", "SynergyDOSettingsV2"}
#: chained runs: settings -> (which of our results feed it)
CHAIN = {
    "TorqueVOSettingsV1": "TorqueTOSettingsV1", "TorqueVOSettingsV2": "TorqueTOSettingsV1",
    **{f"TorqueDOSettingsV{i}": "TorqueVOSettingsV2" for i in range(1, 6)},
    "SynergyVOSettingsV1": "SynergyTOSettingsV3", "SynergyVOSettingsV2": "SynergyTOSettingsV3",
    "SynergyDOSettingsV1": "SynergyVOSettingsV2", "SynergyDOSettingsV2": "SynergyVOSettingsV2",
}


def settings_path(name: str) -> Path:
    folder = "torque_kick_tutorial" if name.startswith("Torque") else "synergy_kick_tutorial"
    return DATA / folder / "CompletedSettingsFiles" / f"{name}.xml"


def original_results(name: str) -> Path:
    return settings_path(name).parent / name.replace("Settings", "Results")


def _run(path: Path, out: Path, **options: Any) -> tuple[Any, float]:
    start = time.perf_counter()
    run = run_settings(path, results_directory=out, **options)
    return run, time.perf_counter() - start


def as_given(name: str, out: Path, **options: Any) -> dict[str, Any]:
    path = settings_path(name)
    ours, wall = _run(path, out, **options)
    theirs = score_solution(path, original_results(name), **options)
    comp = Comparison(ours, theirs)
    return {
        "settings": name, "options": {k: v for k, v in options.items()},
        "status": ours.solution.status, "iterations": ours.solution.iterations,
        "wall_time_s": wall, "solve_time_s": ours.solution.wall_time, "build_time_s": ours.build_time,
        "cost": ours.cost, "original_cost_scored": theirs.initial_cost, "cost_ratio": comp.cost_ratio,
        "original_violations": max_constraint_violation(theirs),
        "rms": {k: {"ours": a, "original": b} for k, (a, b) in comp.rms().items()},
        "final_time": ours.result.final_time,
    }


def chained(name: str, source_dir: Path, out: Path) -> dict[str, Any]:
    path = settings_path(name)
    run, wall = _run(path, out, initial_guess_directory=source_dir, tracked_quantities_directory=source_dir)
    entry = {"settings": name, "from": str(source_dir), "status": run.solution.status,
             "iterations": run.solution.iterations, "wall_time_s": wall, "solve_time_s": run.solution.wall_time,
             "cost": run.cost, "final_time": run.result.final_time}
    if "VO" in name:
        from nmsm.io.storage import read_storage

        trial = run.prepared.settings.trial_name
        model = run.prepared.model
        to_ik = read_storage(source_dir / "IKData" / f"{trial}.sto")
        to_id = read_storage(source_dir / "IDData" / f"{trial}.sto")
        states = run.prepared.data.state_coordinates
        j = [model.coordinate_names.index(c) for c in states]
        angles = np.degrees(np.max(np.abs(run.result.positions[:, j] - to_ik.columns(states))))
        loads = [model.load_label(c) for c in states]
        moments = np.max(np.abs(run.result.inverse_dynamics[:-1, j] - to_id.columns(loads)[:-1]))
        entry.update(vo_vs_to_max_angle_deg=float(angles), vo_vs_to_max_moment_Nm=float(moments))
    return entry


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("/tmp/bench_treatment"))
    parser.add_argument("--only", choices=["torque", "synergy"], default=None)
    parser.add_argument("--skip-chain", action="store_true")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    names = (TORQUE if args.only != "synergy" else []) + (SYNERGY if args.only != "torque" else [])
    results: dict[str, Any] = {"as_given": [], "chained": []}
    out = args.out
    for name in names:
        entry = as_given(name, out / "as_given" / name)
        print(json.dumps(entry), flush=True)
        results["as_given"].append(entry)
        if name in FREE_TIME:
            entry = as_given(name, out / "as_given_original_time" / name, rescale_prescribed_derivatives=False)
            print(json.dumps(entry), flush=True)
            results["as_given"].append(entry)
    if not args.skip_chain:
        ours: dict[str, Path] = {}
        for name in names:
            target = out / "chained" / name
            if name in CHAIN:
                source = ours.get(CHAIN[name])
                if source is None:
                    continue
                entry = chained(name, source, target)
            else:
                run, wall = _run(settings_path(name), target)
                entry = {"settings": name, "status": run.solution.status, "iterations": run.solution.iterations,
                         "wall_time_s": wall, "solve_time_s": run.solution.wall_time, "cost": run.cost}
            ours[name] = target
            print(json.dumps(entry), flush=True)
            results["chained"].append(entry)
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(results, indent=1))
    (out / "results.md").write_text(markdown(results))
    print(markdown(results))


def markdown(results: dict[str, Any]) -> str:
    lines = ["| settings | options | status | iter | wall s | cost | original scored | ratio |",
             "|---|---|---|---|---|---|---|---|"]
    for e in results["as_given"]:
        opts = ",".join(f"{k}={v}" for k, v in e["options"].items()) or "-"
        lines.append(f"| {e['settings']} | {opts} | {e['status']} | {e['iterations']} | {e['wall_time_s']:.1f} | "
                     f"{e['cost']:.4g} | {e['original_cost_scored']:.4g} | {e['cost_ratio']:.3f} |")
    if results["chained"]:
        lines += ["", "| chained | status | iter | wall s | cost | VO-TO max angle deg | VO-TO max moment N·m |",
                  "|---|---|---|---|---|---|---|"]
        for e in results["chained"]:
            lines.append(f"| {e['settings']} | {e['status']} | {e['iterations']} | {e['wall_time_s']:.1f} | "
                         f"{e['cost']:.4g} | {e.get('vo_vs_to_max_angle_deg', '')} | {e.get('vo_vs_to_max_moment_Nm', '')} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()

"""Wall time of Muscle-Tendon Personalization (MTLI + MTP tasks + outputs), run as ``nmsm run`` does.

Cases: the tutorial's ``MTPSettingsV3.xml`` (9 muscles, 1 trial, no SynX) and V1 (SynX),
and Patient 3 (``newMTPSettingsFile.xml``: 34 muscles, 4 trials, 6 coordinates, MTLI with
12 passive trials, SynX with 5 synergies). Results go to a temporary folder. Prints wall
and CPU time per case and the machine load (other processes share the 2 cores).

Usage: ``python benchmarks/bench_mtp.py [v3] [v1] [patient3]``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings
from pathlib import Path

from nmsm.tools.mtp.run import run_settings

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
CASES = {
    "v3": SHARED / "mtp" / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "MTPSettingsV3.xml",
    "v1": SHARED / "mtp" / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "MTPSettingsV1.xml",
    "patient3": SHARED / "mtp" / "patient3_gait_squat" / "newMTPSettingsFile.xml",
}


def bench(name: str) -> dict[str, float]:
    warnings.simplefilter("ignore")
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        wall0, cpu0 = time.perf_counter(), time.process_time()
        outcome = run_settings(CASES[name], results_directory=Path(tmp) / name)
        wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    task = outcome.tasks[-1]
    return {"wall_s": wall, "cpu_s": cpu, "ipopt_iterations": task.iterations, "ipopt_wall_s": task.wall_time,
            "cost": task.cost, "load_before": load_before, "load_after": os.getloadavg()[0]}


def main(names: list[str]) -> None:
    print(f"{'case':10s} {'wall s':>8s} {'cpu s':>8s} {'IPOPT it':>9s} {'IPOPT s':>8s} {'cost':>10s} {'load':>10s}")
    for name in names:
        r = bench(name)
        print(f"{name:10s} {r['wall_s']:8.1f} {r['cpu_s']:8.1f} {r['ipopt_iterations']:9d} {r['ipopt_wall_s']:8.1f} "
              f"{r['cost']:10.4f} {r['load_before']:4.1f}/{r['load_after']:4.1f}", flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cases", nargs="*", metavar="CASE", help=f"cases to time, of {', '.join(CASES)} (default: all)")
    cases = parser.parse_args().cases or list(CASES)
    if unknown := [c for c in cases if c not in CASES]:
        parser.error(f"unknown case {', '.join(unknown)} (choose from {', '.join(CASES)})")
    main(cases)

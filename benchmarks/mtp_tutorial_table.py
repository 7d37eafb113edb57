"""MTP tutorial subject 3, settings V1-V3: our run against the original's solution.

Runs ``MTPSettingsV1..V3.xml`` as they are (results written to a temporary folder),
scores the original's ``*_mtp.osimx`` with our cost function (synergy weights fitted
when SynX is on) and prints a Markdown table (cost, moment RMS per coordinate,
bounds, wall time). Usage: ``python benchmarks/mtp_tutorial_table.py [V1 V2 V3]``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings
from pathlib import Path

from nmsm.tools.mtp.report import (
    ComparisonRow,
    comparison_table,
    moment_rms,
    parameters_from_osimx,
    parameters_within_bounds,
    score_parameters,
)
from nmsm.tools.mtp.run import run_settings

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
TUTORIAL = SHARED / "mtp" / "uf_subject3_tutorial" / "CompletedSettingsFiles"


def compare(version: str, output: Path) -> ComparisonRow:
    settings = TUTORIAL / f"MTPSettings{version}.xml"
    start = time.perf_counter()
    outcome = run_settings(settings, results_directory=output / version)
    wall = time.perf_counter() - start
    setup = outcome.setup
    # the original scored on our task-start data (MTLI result), its own F0 and parameters
    base = outcome.start_data
    data, state = parameters_from_osimx(TUTORIAL / f"MTPResults{version}" / "UF_Subject_3_reduced_muscles_mtp.osimx", base)
    original, _ = score_parameters(data, state, setup.tasks[0])
    synx = setup.data.synx is not None
    ours = moment_rms(output / version, synx=synx)
    theirs = moment_rms(TUTORIAL / f"MTPResults{version}", synx=synx)
    trial = next(iter(ours))
    return ComparisonRow(version, outcome.tasks[-1].cost, original.cost, ours[trial], theirs[trial],
                         parameters_within_bounds(outcome.state), wall, synx)


def main(versions: list[str]) -> str:
    warnings.simplefilter("ignore")
    with tempfile.TemporaryDirectory() as tmp:
        rows = [compare(v, Path(tmp)) for v in versions]
    table = comparison_table(rows)
    print(table)
    return table


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("versions", nargs="*", metavar="VERSION",
                        help="tutorial settings versions, of V1, V2, V3 (default: all three)")
    versions = parser.parse_args().versions or ["V1", "V2", "V3"]
    if unknown := [v for v in versions if v not in ("V1", "V2", "V3")]:
        parser.error(f"unknown version {', '.join(unknown)} (choose from V1, V2, V3)")
    main(versions)

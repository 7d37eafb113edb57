"""Benchmark: the built-in example (``nmsm example``) end to end, and the pipeline's overhead.

1. Generates the synthetic subject into a temporary folder (time of the forward simulation
   and the recordings);
2. runs the example's pipeline up to ``--until`` (default: every stage) and prints each
   stage's wall time and the known-answer comparison;
3. runs the pipeline file again and prints the time of a run where every stage is up to date
   (reading settings, hashing inputs: the runner's own overhead).

    python benchmarks/bench_pipeline.py [--until STAGE] [--keep DIR]

Prints measured numbers only (``time.perf_counter``), with the load average: the target is
"a few minutes on 2 cores" for the whole example on an otherwise idle machine.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--until", help="last stage (jmp ... do); default all")
    parser.add_argument("--keep", help="run in this folder and keep it (default: a temporary folder)")
    args = parser.parse_args(argv)
    from nmsm.examples.example_run import run_example
    from nmsm.examples.subject import make_subject
    from nmsm.tools.pipeline.runner import run_pipeline_file

    folder = Path(args.keep) if args.keep else Path(tempfile.mkdtemp(prefix="nmsm_bench_pipeline_"))
    print(f"load average before: {os.getloadavg()}")
    began = time.perf_counter()
    make_subject(folder)
    subject_time = time.perf_counter() - began
    outcome = run_example(folder, until=args.until, log=None)
    print(outcome.text)
    began = time.perf_counter()
    run_pipeline_file(folder / "pipeline.xml", log=None)
    overhead = time.perf_counter() - began
    print(f"subject generation {subject_time:.1f} s; pipeline {sum(outcome.stage_times.values()):.1f} s "
          f"({', '.join(f'{k} {v:.1f}' for k, v in outcome.stage_times.items())}); "
          f"up-to-date re-run {overhead:.2f} s")
    print(f"load average after: {os.getloadavg()}")
    if not args.keep:
        shutil.rmtree(folder, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Sub-command ``nmsm batch BATCH_FILE [-o RESULTS] [--workers N] [--scheduler ADDRESS] [--timeout S]``."""

from __future__ import annotations

import argparse
from typing import Any

from nmsm.cli_types import positive_float, positive_int


def _batch(args: argparse.Namespace) -> int:
    from nmsm.batch.execute import run_batch

    run = run_batch(args.batch, results_directory=args.results_directory, workers=args.workers,
                    scheduler=args.scheduler, timeout=args.timeout)
    print(run.text())
    return 0 if run.ok else 1


def register(subparsers: Any) -> None:
    from nmsm.batch.execute import SCHEDULER_TIMEOUT

    p = subparsers.add_parser("batch", help="run many settings and pipeline files, and sweeps of settings values, "
                                            "in parallel on Dask (docs/batch.md)")
    p.add_argument("batch", help="batch XML (<BatchTool>; nmsm print-xml batch shows one)")
    p.add_argument("-o", "--results-directory", help="write results here instead of the file's <results_directory>")
    p.add_argument("--workers", type=positive_int, metavar="N",
                   help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on an existing Dask cluster, e.g. tcp://host:8786 (inputs and results on a file "
                        "system every worker sees)")
    p.add_argument("--timeout", type=positive_float, default=SCHEDULER_TIMEOUT, metavar="SECONDS",
                   help=f"how long to wait for --scheduler to answer (default {SCHEDULER_TIMEOUT:g})")
    p.set_defaults(func=_batch)

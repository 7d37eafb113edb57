"""Sub-command ``example``: the built-in synthetic subject, lab data to treatment.

::

    nmsm example [STAGE] [--folder DIR]            # every stage, the report and the known answers
    nmsm example --batch [--workers N]             # its DO swept on Dask (nmsm.examples.batch_example)
"""

from __future__ import annotations

import argparse
from typing import Any

from nmsm.cli_types import positive_int


def _example(args: argparse.Namespace) -> int:
    from nmsm.examples.example_run import run_example

    if args.batch:
        from nmsm.errors import InputError
        from nmsm.examples.batch_example import run_example_batch

        if args.stage or args.strict:
            raise InputError("--batch runs the DO sweep of the whole example", element="nmsm example --batch",
                             expected="no STAGE and no --strict with --batch")
        run = run_example_batch(args.folder, workers=args.workers, rebuild=args.rebuild)
        print(run.text())
        print(f"report: {run.spec.results_directory / 'report.html'}")
        return 0 if run.ok else 1
    outcome = run_example(args.folder, until=args.stage, rebuild=args.rebuild)
    print(outcome.text)
    return 1 if args.strict and not outcome.all_within_tolerance else 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("example", help="the built-in synthetic subject: lab data to treatment, with the "
                                               "known answers")
    p.add_argument("stage", nargs="?", help="run the example up to this stage (jmp, passive, analysis, preprocess, "
                                            "mtp, ncp, gcp, surrogate, to, vo, do); default all")
    p.add_argument("--folder", default="nmsm_example", help="where the subject and results go (default ./nmsm_example)")
    p.add_argument("--rebuild", action="store_true", help="regenerate the subject and redo every stage")
    p.add_argument("--strict", action="store_true", help="exit 1 when a recovered value is out of its tolerance")
    p.add_argument("--batch", action="store_true",
                   help="sweep the DO over 5 weakness levels x 2 synergy scalings from one VO with nmsm batch "
                        "(in FOLDER/batch; docs/batch.md)")
    p.add_argument("--workers", type=positive_int, metavar="N",
                   help="with --batch: worker processes (default: one per core)")
    p.set_defaults(func=_example)

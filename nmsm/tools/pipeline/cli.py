"""Sub-command ``pipeline`` (:mod:`nmsm.tools.pipeline.runner`).

::

    nmsm pipeline PIPELINE.xml [--until STAGE] [--only STAGE ...] [--force STAGE ...] [--rebuild] [--check]
"""

from __future__ import annotations

import argparse
from typing import Any


def _pipeline(args: argparse.Namespace) -> int:
    from nmsm.tools.pipeline.runner import run_pipeline_file

    run = run_pipeline_file(args.pipeline, only=args.only or None, until=args.until, force=args.force or (),
                            rebuild=args.rebuild, check_only=args.check, accept_unconverged=args.accept_unconverged)
    print(run.summary())
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("pipeline", help="run a chained pipeline file (stages skipped when up to date)")
    p.add_argument("pipeline", help="pipeline XML (<PipelineTool>, docs/pipeline.md)")
    p.add_argument("--until", metavar="STAGE", help="stop after this stage")
    p.add_argument("--only", metavar="STAGE", nargs="+", help="run only these stages (others must be up to date)")
    p.add_argument("--force", metavar="STAGE", nargs="+", help="redo these stages even when up to date")
    p.add_argument("--rebuild", action="store_true",
                   help="redo every stage (also the way out of a damaged pipeline_state.json)")
    p.add_argument("--check", action="store_true",
                   help="check the file and every stage's settings, show what would run and how it is wired; "
                        "run and write nothing")
    p.add_argument("--accept-unconverged", action="store_true",
                   help="a stage whose solve did not reach its stopping criterion writes its results (each file "
                        "stamped UNCONVERGED) and the pipeline goes on (default: the stage keeps its last iterate "
                        "in its last_iterate/ folder and the pipeline stops there)")
    p.set_defaults(func=_pipeline)

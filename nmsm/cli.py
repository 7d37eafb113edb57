"""The ``nmsm`` command line.

Sub-commands live with the code they drive: each module in :data:`COMMAND_MODULES`
has ``register(subparsers)`` adding its parsers, each parser's ``func`` default taking
the parsed ``argparse.Namespace`` and returning an exit code.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import warnings
from collections.abc import Sequence

from nmsm import __version__
from nmsm.core.progress import DEFAULT_INTERVAL, progress_every
from nmsm.errors import NmsmError

#: modules whose ``register(subparsers)`` adds sub-commands, in help order
COMMAND_MODULES: tuple[str, ...] = (
    "nmsm.commands",  # run, plugins
    "nmsm.io.settings.cli",  # print-xml, upgrade-settings
    "nmsm.model.cli",  # id, muscle-analysis, markers
    "nmsm.tools.jmp.cli",  # ik
    "nmsm.tools.surrogate.cli",  # surrogate
    "nmsm.tools.preprocess.cli",  # preprocess
    "nmsm.tools.ncp.cli",  # vaf
    "nmsm.plots.cli",  # plot
    "nmsm.tools.pipeline.cli",  # pipeline, example, report, export
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="nmsm",
        description="Neuromusculoskeletal Modeling Pipeline: personalize OpenSim models and optimize treatments.",
    )
    parser.add_argument("--version", action="version", version=f"nmsm {__version__}")
    parser.add_argument("--traceback", action="store_true", help="show Python tracebacks on errors")
    parser.add_argument(
        "--progress", type=float, default=DEFAULT_INTERVAL, metavar="SECONDS",
        help=f"print a solver progress line at most every SECONDS while a solve runs (default {DEFAULT_INTERVAL:g}; 0: off)",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:  # a command family not built yet
                continue
            raise
        module.register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    warnings.simplefilter("default")
    warnings.formatwarning = lambda msg, cat, *a, **k: f"warning: {msg}\n"
    try:
        with progress_every(args.progress):
            return int(args.func(args) or 0)
    except NmsmError as exc:
        if args.traceback:
            raise
        print(f"nmsm: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("nmsm: stopped; the interrupted task wrote nothing, finished tasks and stages are kept", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())

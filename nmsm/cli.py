"""The ``nmsm`` command line.

Sub-commands live with the code they drive: each module in :data:`COMMAND_MODULES`
has ``register(subparsers)`` adding its parsers, each parser's ``func`` default taking
the parsed ``argparse.Namespace`` and returning an exit code.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import signal
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from typing import Any

from nmsm import __version__
from nmsm.cli_types import non_negative_float
from nmsm.core.console import console_output
from nmsm.core.progress import DEFAULT_INTERVAL, progress_every
from nmsm.errors import NmsmError, os_error

#: options of ``nmsm`` itself: they go before the sub-command (``nmsm --progress 5 id ...``)
GLOBAL_OPTIONS: tuple[str, ...] = ("--progress", "--traceback")
#: global options that take a value
_GLOBAL_VALUES = ("--progress",)

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
    "nmsm.tools.pipeline.cli",  # pipeline
    "nmsm.examples.cli",  # example
    "nmsm.report.cli",  # report
    "nmsm.interop.cli",  # export
    "nmsm.batch.cli",  # batch
)


def build_parser() -> argparse.ArgumentParser:
    """The ``nmsm`` parser with every sub-command of :data:`COMMAND_MODULES`."""
    parser = argparse.ArgumentParser(
        prog="nmsm",
        description="Neuromusculoskeletal Modeling Pipeline: personalize OpenSim models and optimize treatments.",
    )
    parser.add_argument("--version", action="version", version=f"nmsm {__version__}")
    parser.add_argument("--traceback", action="store_true", help="show Python tracebacks on errors")
    parser.add_argument(
        "--progress", type=non_negative_float, default=DEFAULT_INTERVAL, metavar="SECONDS",
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


def _commands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Sub-command name -> its parser."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _misplaced_global_option(parser: argparse.ArgumentParser, argv: Sequence[str]) -> str | None:
    """The message for a global option written after the sub-command, else None.

    ``nmsm id --progress 5 ...`` would otherwise be reported as "unrecognized arguments" (or
    as a missing argument, ``5`` having been taken for the model).
    """
    commands = _commands(parser)
    k = 0
    while k < len(argv) and argv[k] not in commands:
        if argv[k] == "--":
            return None
        k += 2 if argv[k] in _GLOBAL_VALUES else 1
    if k >= len(argv):
        return None
    command, sub = argv[k], commands[argv[k]]
    rest = argv[k + 1:]
    for j, token in enumerate(rest):
        if token == "--":
            return None
        option, equals, value = token.partition("=")
        if option in GLOBAL_OPTIONS and option not in sub._option_string_actions:
            if option in _GLOBAL_VALUES and not equals:
                value = rest[j + 1] if j + 1 < len(rest) else "SECONDS"
            example = f"{option} {value}" if option in _GLOBAL_VALUES else option
            return (f"{option} goes before the sub-command: nmsm {example} {command} ... "
                    f"({' and '.join(GLOBAL_OPTIONS)} are options of nmsm itself)")
    return None


@contextlib.contextmanager
def each_warning_once() -> Iterator[None]:
    """Show each warning text once while a command runs: a file read by several steps (the
    preprocessing reads its IK file for IK checks, ID and the muscle analysis) warns from
    several places, which Python's "default" filter would all show."""
    shown: set[str] = set()
    show = warnings.showwarning

    def show_once(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: Any = None, line: str | None = None) -> None:
        if str(message) not in shown:
            shown.add(str(message))
            show(message, category, filename, lineno, file, line)

    warnings.showwarning = show_once
    try:
        yield
    finally:
        warnings.showwarning = show


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line ``argv`` (default: the process's own, ``sys.argv``; then a
    Ctrl-C after the command finished is ignored until the process exits)."""
    parser = build_parser()
    own_command_line = argv is None
    argv = list(sys.argv[1:] if argv is None else argv)
    misplaced = _misplaced_global_option(parser, argv)
    if misplaced:
        parser.error(misplaced)
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    warnings.simplefilter("default")
    warnings.formatwarning = lambda msg, cat, *a, **k: f"warning: {msg}\n"
    status: int | None = None
    try:
        with progress_every(args.progress), console_output(), each_warning_once():
            status = int(args.func(args) or 0)
            if own_command_line:
                _ignore_late_interrupts()
    except NmsmError as exc:
        if args.traceback:
            raise
        print(f"nmsm: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        error = os_error(exc)
        if error is None or args.traceback:
            raise
        print(f"nmsm: error: {error}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        if status is not None:  # the command had finished: its results are complete
            if own_command_line:
                _ignore_late_interrupts()
            return status
        print("nmsm: stopped; the interrupted task wrote no results (a treatment solve keeps its last iterate in "
              "<results>/last_iterate/), finished tasks and stages are kept", file=sys.stderr)
        return 130
    return status


def _ignore_late_interrupts() -> None:
    """Ignore Ctrl-C once the command has finished, so one arriving while nmsm exits (closing
    the OpenSim worker, joining threads) does not turn complete results into a stopped run."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)


if __name__ == "__main__":
    sys.exit(main())

"""Core sub-commands: ``run`` and ``plugins``."""

from __future__ import annotations

import argparse
import io
import os
import sys
from pathlib import Path
from typing import Any


def _run(args: argparse.Namespace) -> int:
    from nmsm.tools.dispatch import run_settings_file

    options = {}
    if args.results_directory:
        options["results_directory"] = args.results_directory
    if args.accept_unconverged:
        options["accept_unconverged"] = True
    if args.start_from:
        options["guess_directory"] = args.start_from
    outcome = run_settings_file(args.settings, **options)
    where = outcome if isinstance(outcome, Path) else getattr(outcome, "results_directory", None)
    if where is not None:  # every tool says where its results went (some print nothing else)
        print(f"nmsm: results in {where}")
    return 0


def _plugins(args: argparse.Namespace) -> int:
    """The registered classes; then one line per plugin problem (exit status 1 if any), so a
    broken plugin does not hide the others."""
    from nmsm.core.registry import TOOL_NAMES, inspect_plugins

    report = inspect_plugins()
    items = report.registry.items(kind=args.kind)
    rows = [("KIND", "NAME", "TOOLS", "DISTRIBUTION", "VERSION")]
    rows += [(it.kind, it.name, "all" if it.tools >= set(TOOL_NAMES) else ",".join(sorted(it.tools)), it.distribution,
              it.version) for it in items]
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
    if report.problems:
        lines += ["", f"{len(report.problems)} plugin problem(s): the classes concerned are not listed above, and "
                      f"every run fails until each is fixed, uninstalled or left out with NMSM_DISABLE_PLUGINS:"]
        lines += [f"  - {p.message}" for p in report.problems]
    try:
        for line in lines:
            print(line)
        sys.stdout.flush()
    except BrokenPipeError:  # `nmsm plugins | head`: the reader has what it wanted
        _discard_stdout()
        return 0
    failed = _check_terms(items) if getattr(args, "check", False) else 0
    return 1 if report.problems or failed else 0


def _check_terms(items: Any) -> int:
    """``nmsm.testing.check_term`` on each registered term class, one line each; the number
    that failed."""
    from nmsm.testing import TermCheckError, check_term

    print()
    failed = 0
    seen: set[type] = set()
    for it in items:
        if it.kind not in ("cost", "constraint") or it.cls in seen:
            continue
        seen.add(it.cls)
        try:
            result = check_term(it.cls)
        except TermCheckError as exc:
            failed += 1
            print(f"FAILED  {it.kind} {it.name}: {exc}")
            continue
        extra = f" (not built: {result.not_built})" if result.not_built else f" (on {result.problem})"
        extra += "".join(f"\n        warning: {w}" for w in result.warnings)
        print(f"ok      {it.kind} {it.name}: {', '.join(result.passed)}{extra}")
    print(f"\n{len(seen) - failed} of {len(seen)} term classes pass nmsm.testing.check_term")
    return failed


def _discard_stdout() -> None:
    """Send the rest of stdout (and its flush at exit) to the null device, so a closed pipe
    prints no 'Exception ignored ... BrokenPipeError' at exit."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (AttributeError, OSError, ValueError, io.UnsupportedOperation):  # not a real file (tests)
        sys.stdout = open(os.devnull, "w", encoding="utf-8")  # noqa: SIM115 - replaces stdout until exit
    finally:
        os.close(devnull)


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("run", help="run the tool named by a settings XML file")
    p.add_argument("settings", help="settings XML (root NMSMPipelineDocument, or an older schema)")
    p.add_argument(
        "-o", "--results-directory",
        help="write results here instead of the settings' <results_directory> (e.g. to keep a tutorial folder untouched)",
    )
    p.add_argument(
        "--accept-unconverged", action="store_true",
        help="write the results of a solve that did not reach its stopping criterion where results go, each file "
             "stamped UNCONVERGED (default: its last iterate and a diagnosis go into RESULTS/last_iterate/ and nmsm "
             "exits with status 1)",
    )
    p.add_argument(
        "--start-from", metavar="DIR",
        help="treatment optimization: start IPOPT from the results in DIR (states, controls, synergy weights; e.g. "
             "the same settings' results on a coarser mesh) instead of the settings' initial guess; the tracked "
             "data and references stay the settings' own",
    )
    p.set_defaults(func=_run)

    from nmsm.core.registry import KINDS

    p = subparsers.add_parser(
        "plugins",
        help="list every registered term, constraint, controller, modifier, contact model and back end, and broken plugins",
    )
    p.add_argument("--kind", choices=list(KINDS), help="only this kind")
    p.add_argument("--check", action="store_true",
                   help="also run nmsm.testing.check_term on every registered cost and constraint term")
    p.set_defaults(func=_plugins)

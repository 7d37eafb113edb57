"""Core sub-commands: ``run`` and ``plugins``."""

from __future__ import annotations

import argparse
from typing import Any


def _run(args: argparse.Namespace) -> int:
    from nmsm.tools.dispatch import run_settings_file

    options = {}
    if args.results_directory:
        options["results_directory"] = args.results_directory
    run_settings_file(args.settings, **options)
    return 0


def _plugins(args: argparse.Namespace) -> int:
    from nmsm.core.registry import get_registry

    items = get_registry().items(kind=args.kind)
    rows = [("KIND", "NAME", "TOOLS", "DISTRIBUTION", "VERSION")]
    rows += [(it.kind, it.name, ",".join(sorted(it.tools)), it.distribution, it.version) for it in items]
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    for r in rows:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("run", help="run the tool named by a settings XML file")
    p.add_argument("settings", help="settings XML (root NMSMPipelineDocument, or an older schema)")
    p.add_argument(
        "-o", "--results-directory",
        help="write results here instead of the settings' <results_directory> (e.g. to keep a tutorial folder untouched)",
    )
    p.set_defaults(func=_run)

    p = subparsers.add_parser("plugins", help="list every registered term, constraint, controller and modifier")
    p.add_argument("--kind", choices=["cost", "constraint", "controller", "modifier"], help="only this kind")
    p.set_defaults(func=_plugins)

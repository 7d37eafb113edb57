"""Sub-commands ``nmsm print-xml TOOL`` and ``nmsm upgrade-settings OLD.xml -o NEW.xml``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from nmsm.io.settings.document import TOOL_ELEMENTS

#: ``print-xml`` tool codes -> tool element
TOOL_CODES = {code: element for element, code in TOOL_ELEMENTS.items()}


def _print_xml(args: argparse.Namespace) -> int:
    from nmsm.io.settings.template import format_template

    text = format_template(TOOL_CODES[args.tool])
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
        print(f"wrote {args.output}", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def _upgrade_settings(args: argparse.Namespace) -> int:
    from nmsm.io.settings.upgrade import upgrade_settings_file

    result = upgrade_settings_file(args.old, args.output)
    if result.schema == "current":
        print(f"{args.old} already uses the current schema; copied to {args.output}", file=sys.stderr)
        return 0
    print(f"{args.old}: schema {result.schema} -> current; wrote {args.output}", file=sys.stderr)
    for note in result.notes:
        print(f"  {note}", file=sys.stderr)
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "print-xml",
        help="write a commented settings template of a tool (defaults and descriptions)",
    )
    p.add_argument("tool", choices=list(TOOL_CODES), help="jmp, mtp, ncp, gcp, to, vo, do or solver")
    p.add_argument("-o", "--output", help="file to write (default: standard output)")
    p.set_defaults(func=_print_xml)

    p = subparsers.add_parser(
        "upgrade-settings",
        help="translate an older settings file (OpenSimDocument, 0.1.0, GpopsDocument) to the current schema",
    )
    p.add_argument("old", help="settings XML in an older schema")
    p.add_argument("-o", "--output", required=True, help="where to write the upgraded settings (not the old file)")
    p.set_defaults(func=_upgrade_settings)

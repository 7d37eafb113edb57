"""Sub-commands ``nmsm print-xml TOOL [-o FILE [--force]]`` and ``nmsm upgrade-settings OLD.xml -o NEW.xml
[--force]``.

``-o`` must name a file in an existing folder; an existing file is replaced only with
``--force``; ``upgrade-settings`` never writes over the old file or a file it names, and both
write atomically (:mod:`nmsm.io.output_file`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from nmsm.io.settings.document import TOOL_ELEMENTS

#: ``print-xml`` tool codes -> tool element
TOOL_CODES = {code: element for element, code in TOOL_ELEMENTS.items()}
#: ``print-xml`` codes of files that are not a tool's settings -> "module:template text"
OTHER_TEMPLATES = {"batch": "nmsm.batch.template:BATCH_TEMPLATE"}


def _template(code: str) -> str:
    import importlib

    from nmsm.io.settings.template import format_template

    if code in OTHER_TEMPLATES:
        module, _, name = OTHER_TEMPLATES[code].partition(":")
        return str(getattr(importlib.import_module(module), name))
    return format_template(TOOL_CODES[code])


def _print_xml(args: argparse.Namespace) -> int:
    from nmsm.io.output_file import check_output, write_output

    text = _template(args.tool)
    if args.output:
        path = check_output(args.output, force=args.force, example_name=f"{args.tool}.xml")
        replaced = path.exists()
        write_output(path, text)
        print(f"wrote {args.output}" + (" (replaced the existing file: --force)" if replaced else ""), file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def _upgrade_settings(args: argparse.Namespace) -> int:
    from nmsm.io.settings.upgrade import upgrade_settings_file

    replaced = " (replaced the existing file: --force)" if Path(args.output).is_file() else ""
    result = upgrade_settings_file(args.old, args.output, force=args.force)
    if result.schema == "current" and not result.notes:
        print(f"{args.old} already uses the current schema; copied to {args.output}{replaced}", file=sys.stderr)
        return 0
    source = "elements of an earlier 1.x release" if result.schema == "current" else f"schema {result.schema}"
    print(f"{args.old}: {source} -> current; wrote {args.output}{replaced}", file=sys.stderr)
    for note in result.notes:
        print(f"  {note}", file=sys.stderr)
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "print-xml",
        help="write a commented settings template of a tool (defaults and descriptions)",
    )
    p.add_argument("tool", choices=[*TOOL_CODES, *OTHER_TEMPLATES],
                   help="jmp, mtp, ncp, gcp, to, vo, do, solver, or batch (a batch file of nmsm batch)")
    p.add_argument("-o", "--output", help="file to write (default: standard output); its folder must exist")
    p.add_argument("--force", action="store_true", help="replace the -o file if it exists")
    p.set_defaults(func=_print_xml)

    p = subparsers.add_parser(
        "upgrade-settings",
        help="translate an older settings file (OpenSimDocument, 0.1.0, GpopsDocument) to the current schema",
    )
    p.add_argument("old", help="settings XML in an older schema")
    p.add_argument("-o", "--output", required=True,
                   help="where to write the upgraded settings: a new file in an existing folder (never the old file "
                        "or a file it names)")
    p.add_argument("--force", action="store_true",
                   help="replace the -o file if it exists (still never the old file or a file it names)")
    p.set_defaults(func=_upgrade_settings)

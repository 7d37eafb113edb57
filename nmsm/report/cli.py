"""Sub-command ``report``: one HTML page of every stage's tables and figures in a results tree.

::

    nmsm report RESULTS_DIR [-o report.html]
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def _report_target(args: argparse.Namespace) -> tuple[Path, Path]:
    """The results tree and the checked HTML file: never an existing non-HTML file of the tree."""
    from nmsm.errors import InputError
    from nmsm.io.output_file import check_default_folder_writable, check_outputs
    from nmsm.report.html import REPORT_FILE

    root = Path(args.results)
    if not root.is_dir():
        raise InputError("not a folder", file=root, expected="a results folder")
    if not args.output:
        check_default_folder_writable(root, f"the report ({REPORT_FILE})")
    target = Path(args.output) if args.output else root / REPORT_FILE
    html = target.suffix.lower() in (".html", ".htm")  # the report reads no HTML: an earlier report is replaced
    folders = {} if html else {root: "the results tree being reported"}
    option = "-o" if args.output else "the default report file"
    check_outputs({option: target}, {}, protected_folders=folders, example_names={option: REPORT_FILE})
    return root, target


def _report(args: argparse.Namespace) -> int:
    """``nmsm report``: the output checked, the page built and written atomically; the
    results tree is only read (figures it lacks are drawn outside it)."""
    from nmsm.report.html import write_report

    root, target = _report_target(args)
    write_report(root, target)
    print(f"wrote {target}")
    return 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser("report", help="one HTML page of every stage's tables and figures in a results tree")
    p.add_argument("results", help="a pipeline results tree or one tool's results folder")
    p.add_argument("-o", "--output", help="HTML file (default: RESULTS/report.html)")
    p.set_defaults(func=_report)

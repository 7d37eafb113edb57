"""``nmsm report RESULTS_DIR``: one HTML page with every stage's tables and figures.

The stages of a pipeline results tree come from its ``pipeline_state.json`` (in pipeline
order, with each stage's kind and time); any other folder is searched for tool results
folders (:func:`nmsm.plots.cli.results_folders`). For each stage: its tables
(:mod:`nmsm.report.tables`) and its figures, embedded as base64 PNG so the page is one file
that can be mailed: the PNGs of ``<stage>/plots`` when there are any (``nmsm plot``),
otherwise drawn by the tool's plot module into a temporary folder that is removed once the
page is built. The report reads the results tree and never writes into it (the page itself
goes where it is told, by default ``<results>/report.html``). The example adds its
known-answer comparison on top.
"""

from __future__ import annotations

import base64
import datetime
import html
import json
import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.output_file import write_output
from nmsm.report.tables import BUILDERS, ReportTable, checks_table

REPORT_FILE = "report.html"
#: pipeline stage kind -> report section kind
KIND_SECTIONS = {"jmp": "jmp", "analysis": "analysis", "mtp": "mtp", "ncp": "ncp", "gcp": "gcp", "to": "treatment",
                 "vo": "treatment", "do": "treatment"}
_STYLE = """
body { font-family: sans-serif; margin: 2em; max-width: 1200px; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 3px 8px; text-align: right; }
th { background: #eee; } td:first-child, th:first-child { text-align: left; }
td.OUT { color: #b00; font-weight: bold; } td.within { color: #070; }
img { max-width: 100%; border: 1px solid #ddd; margin: 4px 0; }
.note { color: #555; font-size: 0.85em; }
"""


def _stages(root: Path) -> list[tuple[str, str, Path, str]]:
    """``(name, section kind, folder, description)`` of the stages in ``root``."""
    state = root / "pipeline_state.json"
    if state.is_file():
        data = json.loads(state.read_text(encoding="utf-8"))
        out = []
        for name, record in data.get("stages", {}).items():
            section = KIND_SECTIONS.get(record.get("kind", ""))
            if section is None:
                continue
            folder = root / record["results_directory"]
            out.append((name, section, folder,
                        f"{record['kind']}, finished {record.get('finished', '')}, {record.get('wall_time', 0):.1f} s"))
        return out
    from nmsm.plots.cli import results_folders

    return [(str(folder.relative_to(root)) or folder.name, tool, folder, tool) for tool, folder in results_folders(root)]


def _table_html(table: ReportTable) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in table.headers)
    body = []
    for row in table.rows:
        cells = "".join(f"<td class=\"{html.escape(c) if c in ('OUT', 'within') else ''}\">{html.escape(c)}</td>"
                        for c in row)
        body.append(f"<tr>{cells}</tr>")
    note = f"<p class=\"note\">{html.escape(table.note)}</p>" if table.note else ""
    return f"<h3>{html.escape(table.title)}</h3><table><tr>{head}</tr>{''.join(body)}</table>{note}"


def _figures(section: str, folder: Path, scratch: Path, log: Callable[[str], None] | None) -> list[Path]:
    """The PNGs of ``folder/plots``, or (none there) those the tool's plot module draws into
    ``scratch`` (a new folder outside the results tree)."""
    from nmsm.plots.cli import PLOTTERS

    plots = folder / "plots"
    existing = sorted(plots.glob("*.png")) if plots.is_dir() else []
    if existing:
        return existing
    tool = "treatment" if section == "treatment" else section
    plotter = next((p for p in PLOTTERS if p.tool == tool), None)
    if plotter is None or not plotter.matches(folder):
        return []
    try:
        return sorted(p for p in plotter.draw(folder, scratch) if Path(p).suffix == ".png")
    except Exception as exc:  # a figure that cannot be drawn must not lose the rest of the report
        if log:
            log(f"report: no figures for {folder} ({type(exc).__name__}: {exc})")
        return []


def _image(path: Path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return f"<div><img alt=\"{html.escape(Path(path).name)}\" src=\"data:image/png;base64,{data}\"></div>"


def _section(name: str, section: str, folder: Path, description: str, scratch: Path,
             log: Callable[[str], None] | None) -> list[str]:
    """The HTML parts of one stage: heading, tables, figures (drawn into ``scratch`` if need be)."""
    parts = [f"<h2>{html.escape(name)}</h2><p class=\"note\">{html.escape(description)}: "
             f"{html.escape(str(folder))}</p>"]
    builder = BUILDERS.get(section)
    if builder is not None:
        try:
            tables = builder(folder)
        except (OSError, ValueError, KeyError, StopIteration, InputError) as exc:
            tables = [ReportTable("tables unavailable", ("reason",), ((f"{type(exc).__name__}: {exc}",),))]
        parts.extend(_table_html(t) for t in tables)
    parts.extend(_image(p) for p in _figures(section, folder, scratch, log))
    return parts


def write_report(results: str | os.PathLike[str], output: str | os.PathLike[str] | None = None, *,
                 checks: Sequence | None = None, title: str | None = None,
                 log: Callable[[str], None] | None = print) -> Path:
    """Write the report of ``results`` (a pipeline tree or a results folder) to ``output``
    (default ``<results>/report.html``) atomically; returns its path. Nothing else is written
    (module docstring)."""
    root = Path(results)
    if not root.is_dir():
        raise InputError("not a folder", file=root, expected="a results folder")
    stages = _stages(root)
    if not stages and not checks:
        raise InputError("no results of JMP, MTP, NCP, GCP or treatment optimization found", file=root,
                         expected="a pipeline results tree or a tool's results folder")
    parts = [f"<h1>{html.escape(title or f'nmsm report: {root.resolve().name}')}</h1>",
             f"<p class=\"note\">{html.escape(str(root.resolve()))}, "
             f"{datetime.datetime.now().isoformat(timespec='seconds')}</p>"]
    if checks:
        parts.append("<h2>Known-answer comparison</h2>" + _table_html(checks_table(checks)))
    with tempfile.TemporaryDirectory(prefix="nmsm-report-") as drawn:
        for k, (name, section, folder, description) in enumerate(stages):
            parts.extend(_section(name, section, folder, description, Path(drawn) / str(k), log))
    page = (f"<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{html.escape(title or 'nmsm report')}</title>"
            f"<style>{_STYLE}</style></head><body>{''.join(parts)}</body></html>\n")
    target = Path(output) if output is not None else root / REPORT_FILE
    write_output(target, page)
    return target

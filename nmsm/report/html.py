"""``nmsm report RESULTS_DIR``: one HTML page with every stage's status, figures and tables.

The stages of a pipeline results tree come from its ``pipeline_state.json`` (in pipeline
order, with each stage's kind and time); any other folder is searched for tool results
folders (:func:`nmsm.plots.cli.results_folders`). The page leads with a status table (one
row per stage: converged or not, solver statuses, headline errors, time;
:mod:`nmsm.report.status`) linking to each stage's section; a section shows the stage's
figures, then its tables (:mod:`nmsm.report.tables`) and summaries collapsed. Figures are
embedded as base64 PNG so the page is one file that can be mailed: the PNGs of
``<stage>/plots`` when there are any (``nmsm plot``), otherwise drawn by the tool's plot
module into a temporary folder that is removed once the page is built. The report reads
the results tree and never writes into it (the page itself goes where it is told, by
default ``<results>/report.html``). A tree with several treatment stages (TO, VO, DO) ends
with their comparison: the first one's kinematics and ground reactions with the others
drawn on them, against the experimental data (:func:`treatment_comparison`). The example
adds its known-answer comparison (collapsed, under the status table). A batch's results
folder (``nmsm batch``) leads with its summary and the figure of each sweep's design goal
against the varied value (:func:`batch_view`, ``batch.html.j2``); its runs' sections show
their tables and only the figures ``nmsm plot`` drew into them, without a comparison.

The page is rendered with Jinja2 from the templates in ``nmsm/report/templates``:
``report.html.j2`` (the page), ``status.html.j2``, ``checks.html.j2``, ``table.html.j2``
and ``stage.html.j2`` (a stage's section). A kind of stage gets its own section by adding
``stages/<kind>.html.j2`` (usually ``{% extends "stage.html.j2" %}`` overriding a block),
its tables by an entry in :data:`nmsm.report.tables.BUILDERS` and its status row by one in
:data:`nmsm.report.status.STATUS_READERS`.
"""

from __future__ import annotations

import base64
import datetime
import json
import os
import re
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import attrs

from nmsm.errors import InputError
from nmsm.io.output_file import write_output
from nmsm.report.status import StageStatus, stage_status
from nmsm.report.tables import BUILDERS, ReportTable, ReportText, checks_table

REPORT_FILE = "report.html"
#: pipeline stage kind -> report section kind
KIND_SECTIONS = {"jmp": "jmp", "analysis": "analysis", "mtp": "mtp", "ncp": "ncp", "gcp": "gcp", "to": "treatment",
                 "vo": "treatment", "do": "treatment"}


@attrs.frozen
class Figure:
    """An embedded figure: file name and ``data:`` URI of the PNG."""

    name: str
    uri: str


@attrs.define
class StageView:
    """What the templates show of one stage. ``kind`` is the section kind (None: a pipeline
    stage without results to show, such as preprocessing; it gets a status row only)."""

    name: str
    kind: str | None
    folder: Path
    description: str
    seconds: float | None = None
    #: the kind shown in the status table (the pipeline's stage kind, e.g. ``to``)
    label: str = ""
    #: False for sections that are no stage (the treatment comparison): no status row
    is_stage: bool = True
    status: StageStatus = attrs.field(factory=StageStatus)
    tables: list[ReportTable] = attrs.field(factory=list)
    texts: list[ReportText] = attrs.field(factory=list)
    figures: list[Figure] = attrs.field(factory=list)

    @property
    def has_section(self) -> bool:
        return self.kind is not None

    @property
    def anchor(self) -> str:
        return "stage-" + re.sub(r"[^A-Za-z0-9_-]+", "-", self.name).strip("-")

    @property
    def seconds_text(self) -> str:
        seconds = self.seconds if self.seconds is not None else self.status.seconds
        return "" if seconds is None else f"{seconds:.1f}"


def _stages(root: Path) -> list[StageView]:
    """The stages of ``root``, in pipeline order (module docstring)."""
    state = root / "pipeline_state.json"
    if state.is_file():
        data = json.loads(state.read_text(encoding="utf-8"))
        out = []
        for name, record in data.get("stages", {}).items():
            kind = record.get("kind", "")
            finished = record.get("finished", "")
            out.append(StageView(name, KIND_SECTIONS.get(kind), root / record["results_directory"],
                                 f"{kind}, finished {finished}" if finished else kind, record.get("wall_time"), kind))
        return out
    from nmsm.plots.cli import results_folders

    return [StageView(str(folder.relative_to(root)) if folder != root else folder.resolve().name, tool, folder, tool,
                      label=tool) for tool, folder in results_folders(root)]


def _figures(section: str, folder: Path, scratch: Path, log: Callable[[str], None] | None, *,
             draw: bool = True) -> list[Path]:
    """The PNGs of ``folder/plots``, or (none there, and ``draw``) those the tool's plot module
    draws into ``scratch`` (a new folder outside the results tree)."""
    from nmsm.plots.cli import PLOTTERS

    plots = folder / "plots"
    existing = sorted(plots.glob("*.png")) if plots.is_dir() else []
    if existing or not draw:
        return existing
    tool = "treatment" if section == "treatment" else section
    plotter = next((p for p in PLOTTERS if p.tool == tool), None)
    if plotter is None or not plotter.matches(folder):
        return []
    try:
        return [Path(p) for p in plotter.draw(folder, scratch) if Path(p).suffix == ".png"]  # the plotter's order
    except Exception as exc:  # a figure that cannot be drawn must not lose the rest of the report
        if log:
            log(f"report: no figures for {folder} ({type(exc).__name__}: {exc})")
        return []


def _figure(path: Path) -> Figure:
    data = base64.b64encode(Path(path).read_bytes()).decode()
    return Figure(Path(path).name, f"data:image/png;base64,{data}")


def _fill(stage: StageView, scratch: Path, log: Callable[[str], None] | None, *, draw: bool = True) -> None:
    """Read one stage's status, tables, texts and figures (drawn into ``scratch`` if need be
    and ``draw``)."""
    if stage.kind is None:
        return
    stage.status = stage_status(stage.kind, stage.folder)
    builder = BUILDERS.get(stage.kind)
    if builder is not None:
        try:
            parts = builder(stage.folder)
        except (OSError, ValueError, KeyError, StopIteration, InputError) as exc:
            parts = [ReportText("tables unavailable", f"{type(exc).__name__}: {exc}")]
        stage.tables = [p for p in parts if isinstance(p, ReportTable)]
        stage.texts = [p for p in parts if isinstance(p, ReportText)]
    stage.figures = [_figure(p) for p in _figures(stage.kind, stage.folder, scratch, log, draw=draw)]


def treatment_comparison(stages: Sequence[StageView], scratch: Path, log: Callable[[str], None] | None
                         ) -> StageView | None:
    """A section overlaying the treatment stages of one trial (TO, VO, DO, ...) against the
    experimental data: the first stage's kinematics and ground reactions with the others
    drawn on them; None with fewer than two such stages."""
    from nmsm.plots.treatment import is_treatment_results, plot_treatment_results

    runs = [s for s in stages if s.kind == "treatment" and is_treatment_results(s.folder)]
    if len(runs) < 2:
        return None
    try:
        drawn = plot_treatment_results(runs[0].folder, scratch, compare=[s.folder for s in runs[1:]],
                                       prefix="compare_")
    except Exception as exc:  # a figure that cannot be drawn must not lose the rest of the report
        if log:
            log(f"report: no comparison figures ({type(exc).__name__}: {exc})")
        return None
    shown = [p for p in drawn if p.stem.endswith(("_kinematics", "_ground_reactions"))]
    names = " vs ".join(s.name for s in runs)
    view = StageView(f"Treatment comparison: {names}", "comparison", runs[0].folder,
                     f"{names}, drawn on the figures of {runs[0].name}", is_stage=False)
    view.figures = [_figure(p) for p in shown]
    return view


#: columns of the batch summary shown in the report (after the run and the swept parameters)
BATCH_COLUMNS = ("status", "ipopt_status", "iterations", "objective", "objective_change", "tracking_rms_deg",
                 "wall_time_s", "attempts", "message")


def batch_view(root: Path, scratch: Path) -> dict[str, Any]:
    """The batch section of ``root`` (``batch_summary.csv`` of ``nmsm batch``,
    :mod:`nmsm.batch.summary`): the summary table and the figure of each sweep
    (``plots/sweep_*.png``, or drawn into ``scratch``)."""
    from nmsm.batch.summary import SUMMARY_FILE, draw_sweeps, parameter_columns, read_summary

    columns, rows = read_summary(root / SUMMARY_FILE)
    shown = ["run", *parameter_columns(columns), *BATCH_COLUMNS]
    counts = ", ".join(f"{sum(r['status'] == s for r in rows)} {s}" for s in dict.fromkeys(r["status"] for r in rows))
    table = ReportTable(f"{len(rows)} runs ({counts})", tuple(shown),
                        tuple(tuple(r.get(c, "")[:200] for c in shown) for r in rows),
                        note=f"{root / SUMMARY_FILE}; design goal = the final objective, its change from the "
                             "starting point (the parent's results for a warm start); tracking RMS = modeled - "
                             "tracked coordinates (deg). Each run's section below shows its figures when "
                             "nmsm plot has drawn them into its folder.")
    figures = sorted((root / "plots").glob("sweep_*.png"))
    if not figures:
        scratch.mkdir(parents=True, exist_ok=True)
        figures = draw_sweeps(columns, rows, scratch)
    return {"table": table, "figures": [_figure(p) for p in figures]}


def _environment() -> Any:
    import jinja2

    return jinja2.Environment(loader=jinja2.PackageLoader("nmsm.report", "templates"),
                              autoescape=jinja2.select_autoescape(("html", "j2")), undefined=jinja2.StrictUndefined,
                              trim_blocks=True, lstrip_blocks=True)


def _checks_view(checks: Sequence) -> dict[str, Any]:
    verdicts = [c.ok for c in checks]
    return {"table": checks_table(checks), "within": verdicts.count(True), "out": verdicts.count(False),
            "reported": verdicts.count(None)}


def render_report(root: Path, stages: Sequence[StageView], *, checks: Sequence | None = None,
                  title: str | None = None, batch: dict[str, Any] | None = None) -> str:
    """The page's HTML for ``stages`` (already filled) of the results tree ``root``."""
    from nmsm import __version__

    return _environment().get_template("report.html.j2").render(
        title=title or f"nmsm report: {'/'.join(root.resolve().parts[-2:])}", root=str(root.resolve()),
        written=datetime.datetime.now().isoformat(timespec="seconds"), version=__version__,
        stages=list(stages), checks=_checks_view(checks) if checks else None, batch=batch)


def write_report(results: str | os.PathLike[str], output: str | os.PathLike[str] | None = None, *,
                 checks: Sequence | None = None, title: str | None = None,
                 log: Callable[[str], None] | None = print) -> Path:
    """Write the report of ``results`` (a pipeline tree or a results folder) to ``output``
    (default ``<results>/report.html``) atomically; returns its path. Nothing else is written
    (module docstring)."""
    root = Path(results)
    if not root.is_dir():
        raise InputError("not a folder", file=root, expected="a results folder")
    from nmsm.batch.summary import SUMMARY_FILE

    is_batch = (root / SUMMARY_FILE).is_file()
    stages = _stages(root)
    if not any(s.has_section for s in stages) and not checks and not is_batch:
        raise InputError("no results of JMP, MTP, NCP, GCP or treatment optimization found", file=root,
                         expected="a pipeline results tree or a tool's results folder")
    with tempfile.TemporaryDirectory(prefix="nmsm-report-") as drawn:
        # a batch's runs: their tables, only the figures `nmsm plot` drew, no comparison (many runs)
        batch = batch_view(root, Path(drawn) / "batch") if is_batch else None
        for k, stage in enumerate(stages):
            _fill(stage, Path(drawn) / str(k), log, draw=not is_batch)
        comparison = None if is_batch else treatment_comparison(stages, Path(drawn) / "comparison", log)
        if comparison is not None:
            stages.append(comparison)
        page = render_report(root, stages, checks=checks, title=title, batch=batch)
    target = Path(output) if output is not None else root / REPORT_FILE
    write_output(target, page)
    return target

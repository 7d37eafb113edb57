"""``batch_summary.csv`` and the figure of each sweep.

One row per run: the run, its patient, sweep and variant, one column per swept parameter
(its value), then :data:`FIGURES` (status, IPOPT status, iterations, the design goal's value
and change from the starting point, tracking RMS, wall and CPU time, worker, attempts, results
folder, message). :func:`draw_sweeps` draws, for each sweep, the design goal (the final
objective) and the tracking RMS against the first parameter, one line per value of the
others.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from pathlib import Path

from nmsm.batch.outcome import FINISHED, RunOutcome
from nmsm.batch.sweep import RunPlan

SUMMARY_FILE = "batch_summary.csv"
HEAD = ("run", "patient", "sweep", "variant")
FIGURES = ("status", "ipopt_status", "iterations", "objective", "initial_objective", "objective_change",
           "tracking_rms_deg", "wall_time_s", "cpu_time_s", "worker", "attempts", "results_directory", "message")


def _g(value: float | None) -> str:
    return "" if value is None else f"{value:.6g}"


def summary_rows(plans: Sequence[RunPlan], outcomes: dict[str, RunOutcome]) -> tuple[list[str], list[dict[str, str]]]:
    """(columns, rows) of the summary, in the batch file's order."""
    parameters = list(dict.fromkeys(name for plan in plans for name, _ in plan.varied))
    columns = [*HEAD, *parameters, *FIGURES]
    rows = []
    for plan in plans:
        outcome = outcomes[plan.name]
        row = {"run": plan.name, "patient": plan.patient, "sweep": plan.entry if plan.varied else "",
               "variant": plan.variant}
        row.update({name: "" for name in parameters})
        row.update(dict(plan.varied))
        row.update({
            "status": outcome.status, "ipopt_status": outcome.ipopt_status,
            "iterations": "" if outcome.iterations is None else str(outcome.iterations),
            "objective": _g(outcome.objective), "initial_objective": _g(outcome.initial_objective),
            "objective_change": _g(outcome.objective_change), "tracking_rms_deg": _g(outcome.tracking_rms),
            "wall_time_s": "" if outcome.wall_time is None else f"{outcome.wall_time:.2f}",
            "cpu_time_s": "" if outcome.cpu_time is None else f"{outcome.cpu_time:.2f}",
            "worker": outcome.worker, "attempts": str(outcome.attempts),
            "results_directory": plan.folder.relative_to(plan.results_root).as_posix(),
            "message": " ".join(outcome.message.split()),
        })
        rows.append(row)
    return columns, rows


def summary_text(columns: Sequence[str], rows: Sequence[dict[str, str]]) -> str:
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(columns), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


def write_summary(folder: Path, plans: Sequence[RunPlan], outcomes: dict[str, RunOutcome]) -> Path:
    """Write ``<folder>/batch_summary.csv`` (atomically); returns its path."""
    from nmsm.io.output_file import write_output

    columns, rows = summary_rows(plans, outcomes)
    path = folder / SUMMARY_FILE
    write_output(path, summary_text(columns, rows))
    return path


def read_summary(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    """(columns, rows) of a ``batch_summary.csv``."""
    with open(path, encoding="utf-8", newline="") as handle:
        reader = csv.DictReader(handle)
        return list(reader.fieldnames or ()), list(reader)


def parameter_columns(columns: Sequence[str]) -> list[str]:
    return [c for c in columns if c not in HEAD and c not in FIGURES]


def _float(text: str) -> float | None:
    try:
        return float(text)
    except (TypeError, ValueError):
        return None


def draw_sweeps(columns: Sequence[str], rows: Sequence[dict[str, str]], folder: Path) -> list[Path]:
    """One PNG per sweep with finished runs (module docstring) in ``folder``; their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from nmsm.batch.sweep import folder_name

    parameters = parameter_columns(columns)
    sweeps = list(dict.fromkeys(r["sweep"] for r in rows if r["sweep"]))
    written = []
    for sweep in sweeps:
        runs = [r for r in rows if r["sweep"] == sweep]
        varied = [p for p in parameters if any(r[p] for r in runs)]
        done = [r for r in runs if r["status"] in FINISHED and _float(r["objective"]) is not None]
        if not varied or not done:
            continue
        x_name, others = varied[0], varied[1:]
        values = list(dict.fromkeys(r[x_name] for r in runs))
        numeric = all(_float(v) is not None for v in values)
        position = {v: (_float(v) if numeric else k) for k, v in enumerate(values)}
        panels = [("objective", "design goal (final objective)")]
        if any(_float(r["tracking_rms_deg"]) is not None for r in done):
            panels.append(("tracking_rms_deg", "tracking RMS, modeled - tracked (deg)"))
        figure, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4.2), squeeze=False)
        groups = list(dict.fromkeys(tuple(r[o] for o in others) for r in done))
        for ax, (column, label) in zip(axes[0], panels):
            for group in groups:
                members = sorted((r for r in done if tuple(r[o] for o in others) == group),
                                 key=lambda r: position[r[x_name]])
                points = [(position[r[x_name]], _float(r[column])) for r in members if _float(r[column]) is not None]
                if not points:
                    continue
                legend = ", ".join(f"{o} = {v}" for o, v in zip(others, group)) or sweep
                ax.plot([p[0] for p in points], [p[1] for p in points], "o-", label=legend)
            ax.set_xlabel(x_name)
            ax.set_ylabel(label)
            if not numeric:
                ax.set_xticks(range(len(values)), values)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8)
        failed = len(runs) - len(done)
        note = f" ({failed} of {len(runs)} runs not finished)" if failed else ""
        figure.suptitle(f"sweep '{sweep}': {len(done)} runs{note}")
        figure.tight_layout()
        path = folder / f"sweep_{folder_name(sweep)}.png"
        figure.savefig(path, dpi=110)
        plt.close(figure)
        written.append(path)
    return written

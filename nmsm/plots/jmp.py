"""Figures of a Joint Model Personalization results folder.

``nmsm plot RESULTS_DIR`` can call :func:`plot_jmp_results` when :func:`is_jmp_results` is
true for the folder (it holds ``jmp_results.json``, see :mod:`nmsm.tools.jmp.run`).
Figures (PNG, written to ``RESULTS_DIR/plots`` unless ``output_dir`` is given):

``jmp_<task folder>.png``  per task: RMS and maximum distance error of each marker before
                           and after (bars, mm), and the RMS over markers frame by frame
                           before and after (mm over s)
``jmp_summary.png``        every task's RMS error of all its markers and of each joint's
                           markers, before and after (mm)
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.io.storage import read_storage
from nmsm.plots import style
from nmsm.plots.convergence import plot_results_convergence

RESULTS_FILE = "jmp_results.json"


def is_jmp_results(folder: str | os.PathLike[str]) -> bool:
    """True for a folder written by ``nmsm run`` on JMP settings."""
    return (Path(folder) / RESULTS_FILE).is_file()


def _pyplot() -> Any:
    return style.pyplot()


def _task_figure(plt: Any, folder: Path, task: dict[str, Any], target: Path) -> Path:
    # NaN: the marker is missing in that frame
    before = read_storage(folder / task["folder"] / "marker_errors_before.sto", allow_nan=lambda label: True)
    after = read_storage(folder / task["folder"] / "marker_errors_after.sto", allow_nan=lambda label: True)
    names = list(before.labels)
    mm_before, mm_after = 1000 * before.data, 1000 * after.data
    fig, (bars, lines) = plt.subplots(2, 1, figsize=(max(6.0, 0.55 * len(names) + 2), 7.5))
    x = np.arange(len(names))
    width = 0.38
    bars.bar(x - width / 2, np.sqrt(np.nanmean(mm_before**2, axis=0)), width, label="RMS before", color="#c44e52")
    bars.bar(x + width / 2, np.sqrt(np.nanmean(mm_after**2, axis=0)), width, label="RMS after", color="#4c72b0")
    bars.scatter(x - width / 2, np.nanmax(mm_before, axis=0), marker="_", s=120, color="#7f1d1d", label="max before")
    bars.scatter(x + width / 2, np.nanmax(mm_after, axis=0), marker="_", s=120, color="#1e3a8a", label="max after")
    bars.set_xticks(x, names, rotation=60, ha="right", fontsize=8)
    bars.set_ylabel("marker distance error (mm)")
    bars.set_title(task["label"])
    bars.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    lines.plot(before.time, np.sqrt(np.nanmean(mm_before**2, axis=1)), color="#c44e52", label="before")
    lines.plot(after.time, np.sqrt(np.nanmean(mm_after**2, axis=1)), color="#4c72b0", label="after")
    lines.set_xlabel("time (s)")
    lines.set_ylabel("RMS over markers (mm)")
    lines.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    fig.savefig(target)
    plt.close(fig)
    return target


def _summary_figure(plt: Any, tasks: list[dict[str, Any]], target: Path) -> Path:
    labels, before, after = [], [], []
    for task in tasks:
        for row in task["errors"]:
            if row["group"].startswith("marker "):
                continue
            group = "all" if row["group"] == "all markers" else row["group"].split(" (")[0]
            labels.append(f"{task['label'].split(':')[0]}\n{group}")
            before.append(1000 * row["rms_before"])
            after.append(1000 * row["rms_after"])
    fig, ax = plt.subplots(figsize=(max(6.0, 1.1 * len(labels) + 2), 4.5))
    x = np.arange(len(labels))
    ax.bar(x - 0.2, before, 0.4, label="before", color="#c44e52")
    ax.bar(x + 0.2, after, 0.4, label="after", color="#4c72b0")
    ax.set_xticks(x, labels, fontsize=7)
    ax.set_ylabel("RMS marker distance error (mm)")
    ax.set_title("Joint Model Personalization")
    ax.legend(loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.tight_layout()
    fig.savefig(target)
    plt.close(fig)
    return target


def plot_jmp_results(results_dir: str | os.PathLike[str], output_dir: str | os.PathLike[str] | None = None) -> list[Path]:
    """Write the figures listed in the module docstring; returns their paths."""
    folder = Path(results_dir)
    summary_file = folder / RESULTS_FILE
    if not summary_file.is_file():
        raise FileNotFoundError(f"{folder} holds no {RESULTS_FILE}: not a JMP results folder")
    summary = json.loads(summary_file.read_text(encoding="utf-8"))
    out = Path(output_dir) if output_dir is not None else folder / "plots"
    out.mkdir(parents=True, exist_ok=True)
    plt = _pyplot()
    paths = [_task_figure(plt, folder, task, out / f"jmp_{task['folder']}.png") for task in summary["tasks"]]
    paths.append(_summary_figure(plt, summary["tasks"], out / "jmp_summary.png"))
    convergence = plot_results_convergence(folder, out, "JMP")
    if convergence is not None:
        paths.append(convergence)
    return paths

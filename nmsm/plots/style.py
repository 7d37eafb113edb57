"""One look for every figure nmsm draws (``nmsm plot``, the report).

:func:`pyplot` returns matplotlib's ``pyplot`` (non-interactive Agg back end) with
:data:`STYLE` applied; every plot module gets its ``pyplot`` here. Conventions:

- the solution is a solid line (:data:`SOLUTION`), experimental or tracked data dashed
  black (:data:`EXPERIMENTAL`), other runs compared with it solid in the next colours;
- the x axis is percent of the gait cycle when the trial is one (:func:`cycle_axis`), time
  in s otherwise, and says which; every y axis names its unit;
- legends go outside the data, under the panels (:func:`legend_below`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

STYLE: dict[str, Any] = {
    "figure.dpi": 100,
    "savefig.dpi": 100,
    "savefig.bbox": "tight",
    "font.size": 9,
    "axes.titlesize": 9,
    "axes.labelsize": 8,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "legend.fontsize": 8,
    "legend.frameon": False,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "lines.linewidth": 1.3,
    "figure.titlesize": 11,
}
#: line styles of the solution, of experimental / tracked data and of compared runs
SOLUTION: dict[str, Any] = {"color": "C0", "lw": 1.5}
EXPERIMENTAL: dict[str, Any] = {"color": "k", "ls": "--", "lw": 1.2}
COMPARED_COLORS = ("C1", "C2", "C3", "C4", "C5", "C6")
#: x-axis labels
PERCENT_CYCLE = "gait cycle (%)"
TIME = "time (s)"


def pyplot() -> Any:
    """matplotlib's ``pyplot`` on the Agg back end with :data:`STYLE` applied."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.rcParams.update(STYLE)
    return plt


def grid(n: int, columns: int = 3) -> tuple[int, int]:
    """(rows, columns) of a grid of ``n`` panels, at most ``columns`` wide."""
    cols = max(1, min(n, columns))
    return (max(n, 1) + cols - 1) // cols, cols


def panels(n: int, *, columns: int = 3, size: tuple[float, float] = (3.6, 2.5)) -> tuple[Any, Any, list[Any]]:
    """``(pyplot, figure, axes)`` with ``n`` panels of ``size`` inches; unused panels hidden."""
    plt = pyplot()
    rows, cols = grid(n, columns)
    fig, axes = plt.subplots(rows, cols, figsize=(size[0] * cols, size[1] * rows), squeeze=False)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        ax.axis("off")
    return plt, fig, flat[:n]


def cycle_axis(time: np.ndarray, gait_cycle: bool, start: float | None = None,
               end: float | None = None) -> tuple[np.ndarray, str]:
    """The x values and label of a trial's figures: percent of ``[start, end]`` (default the
    trial's first and last time) when the trial is a gait cycle, else the time (s)."""
    time = np.asarray(time, dtype=float)
    if not gait_cycle or time.size < 2:
        return time, TIME
    t0 = time[0] if start is None else start
    t1 = time[-1] if end is None else end
    return 100.0 * (time - t0) / (t1 - t0), PERCENT_CYCLE


def legend_below(fig: Any, axes: Sequence[Any] | None = None) -> None:
    """One legend for the figure under its panels, outside the data (labels deduplicated)."""
    handles, labels = [], []
    for ax in axes if axes is not None else fig.axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            if label not in labels and not label.startswith("_"):
                handles.append(handle)
                labels.append(label)
    if handles:
        fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=min(len(labels), 5))


def save(plt: Any, fig: Any, path: Path, title: str | None = None) -> Path:
    """Title, legend under the panels, tight layout; write ``path`` (PNG) and close."""
    if title:
        fig.suptitle(title)
    legend_below(fig)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path

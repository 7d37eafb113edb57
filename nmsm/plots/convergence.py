"""Convergence figures: the objective and the constraint violation (or, for problems without
constraints, the optimality measure) per iteration of every solve of a results folder.

``plot_histories`` draws one panel pair for any solves; ``plot_results_convergence`` draws
the ``convergence.tsv`` table a tool writes (:mod:`nmsm.core.convergence`) as
``<out>/convergence.png``; the treatment tools draw IPOPT's own log the same way.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from nmsm.core.convergence import CONVERGENCE_TABLE, ConvergenceHistory, read_convergence_table
from nmsm.plots import style

#: file name of the figure in a plots folder
CONVERGENCE_FIGURE = "convergence.png"


#: values below it (zero violations of a feasible iterate) are drawn at it on the log axes
LOG_FLOOR = 1e-16


def _positive(values: np.ndarray) -> np.ndarray:
    """``|values|`` for a log axis, at least :data:`LOG_FLOOR` (non-finite values stay gaps)."""
    return np.maximum(np.abs(values), LOG_FLOOR)


def plot_histories(histories: Mapping[str, ConvergenceHistory | None], path: Path, title: str,
                   iteration_label: str = "iteration") -> Path | None:
    """Two panels: the objective per iteration, and the largest constraint violation (solves
    with constraints) or the optimality measure (solves without); one line per solve.
    None when no solve has iterations."""
    solves = {name: h for name, h in histories.items() if h is not None and h.n_iterations > 0}
    if not solves:
        return None
    from matplotlib.ticker import MaxNLocator

    plt, fig, (cost, second) = style.panels(2, columns=2, size=(4.5, 3.0))
    several = len(solves) > 1
    any_violation = any(h.violation is not None for h in solves.values())
    for k, (name, history) in enumerate(solves.items()):
        line = dict(style.SOLUTION) if not several else {"color": f"C{k % 10}"}
        label = name if several else "objective"
        x = np.arange(history.n_iterations)
        cost.semilogy(x, _positive(history.cost), label=label, **{**line, "ls": "-"})
        column = history.violation if any_violation else history.optimality
        if column is not None:
            second.semilogy(x, _positive(column), label="_" + name if several else
                            ("constraint violation" if any_violation else "optimality"),
                            **({"color": "C3"} if not several else line))
    cost.set_ylabel("objective")
    second.set_ylabel("largest constraint violation" if any_violation else "optimality (largest gradient entry)")
    for ax in (cost, second):
        ax.set_xlabel(iteration_label)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    return style.save(plt, fig, path, title)


def plot_results_convergence(folder: Path, out_dir: Path, tool: str) -> Path | None:
    """Draw ``folder/convergence.tsv`` as ``out_dir/convergence.png`` titled by ``tool``;
    None when the folder has no table or the table no iterations."""
    table = folder / CONVERGENCE_TABLE
    if not table.is_file():
        return None
    return plot_histories(read_convergence_table(table), out_dir / CONVERGENCE_FIGURE,
                          f"{tool}: convergence per solve")

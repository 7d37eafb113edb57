"""Per-iteration convergence histories of solves, and their table in a results folder.

Every back end records one :class:`ConvergenceHistory` per solve (IPOPT: objective, largest
constraint violation ``inf_pr`` and dual infeasibility ``inf_du`` of each iterate as IPOPT
reports them; least squares: ``sum(r**2)`` and the largest gradient entry of each accepted
iterate, with respect to the solver's scaled variables). A tool writes the histories of its
solves as one tab-separated table, ``convergence.tsv``, one row per solve and iteration::

    solve	iteration	cost	constraint_violation	optimality
    task_1	0	412.3	0.0012	88.1

An empty cell means the solver does not report that quantity (no constraints: no violation).
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path

import attrs
import numpy as np

#: the file name of the table in a results folder
CONVERGENCE_TABLE = "convergence.tsv"
COLUMNS = ("solve", "iteration", "cost", "constraint_violation", "optimality")


def _vector(values: Iterable[float] | None) -> np.ndarray | None:
    return None if values is None else np.asarray(list(values), dtype=float).ravel()


@attrs.frozen
class ConvergenceHistory:
    """One solve's iterates: ``cost`` (n,) the objective, ``violation`` (n,) the largest
    constraint violation or None without constraints, ``optimality`` (n,) the solver's
    optimality measure (IPOPT's dual infeasibility, the least-squares gradient's largest entry)
    or None; iteration 0 is the start."""

    cost: np.ndarray = attrs.field(converter=_vector)
    violation: np.ndarray | None = attrs.field(default=None, converter=_vector)
    optimality: np.ndarray | None = attrs.field(default=None, converter=_vector)

    def __attrs_post_init__(self) -> None:
        for name in ("violation", "optimality"):
            column = getattr(self, name)
            if column is not None and column.shape != self.cost.shape:
                raise ValueError(f"{name} has {column.size} iterations, cost {self.cost.size}")

    @property
    def n_iterations(self) -> int:
        """Number of recorded iterates (the start included)."""
        return int(self.cost.size)

    def followed_by(self, later: ConvergenceHistory | None) -> ConvergenceHistory:
        """This history and then ``later``'s (a solve restarted from another point), as one;
        a column only one of them has is dropped."""
        if later is None:
            return self

        def joined(a: np.ndarray | None, b: np.ndarray | None) -> np.ndarray | None:
            return None if a is None or b is None else np.concatenate([a, b])

        return ConvergenceHistory(np.concatenate([self.cost, later.cost]), joined(self.violation, later.violation),
                                  joined(self.optimality, later.optimality))

    @classmethod
    def from_ipopt_stats(cls, stats: Mapping[str, object]) -> ConvergenceHistory | None:
        """The history in CasADi's IPOPT ``stats()['iterations']``; None when it holds none."""
        iterations = stats.get("iterations")
        if not isinstance(iterations, Mapping) or not iterations.get("obj"):
            return None
        return cls(cost=iterations["obj"], violation=iterations.get("inf_pr"), optimality=iterations.get("inf_du"))


def _cell(value: float) -> str:
    return "" if not math.isfinite(value) else f"{value:.10g}"


def format_convergence_table(histories: Mapping[str, ConvergenceHistory | None]) -> str:
    """The table of the module docstring for ``histories`` (solve name -> history, in order;
    solves without a history are left out)."""
    stream = io.StringIO()
    writer = csv.writer(stream, delimiter="\t", lineterminator="\n")
    writer.writerow(COLUMNS)
    for name, history in histories.items():
        if history is None:
            continue
        n = history.n_iterations
        violation = history.violation if history.violation is not None else np.full(n, np.nan)
        optimality = history.optimality if history.optimality is not None else np.full(n, np.nan)
        for k in range(n):
            writer.writerow((name, k, _cell(history.cost[k]), _cell(violation[k]), _cell(optimality[k])))
    return stream.getvalue()


def write_convergence_table(path: str | os.PathLike[str], histories: Mapping[str, ConvergenceHistory | None]) -> Path:
    """Write :func:`format_convergence_table` of ``histories`` to ``path``."""
    target = Path(path)
    target.write_text(format_convergence_table(histories), encoding="utf-8")
    return target


def read_convergence_table(path: str | os.PathLike[str]) -> dict[str, ConvergenceHistory]:
    """The histories of a table written by :func:`write_convergence_table`, in file order."""
    rows: dict[str, list[tuple[float, float, float]]] = {}
    with Path(path).open(encoding="utf-8", newline="") as stream:
        reader = csv.DictReader(stream, delimiter="\t")
        for row in reader:
            values = tuple(float(row[c]) if row[c] else math.nan for c in COLUMNS[2:])
            rows.setdefault(row["solve"], []).append(values)  # type: ignore[arg-type]
    histories = {}
    for name, values in rows.items():
        table = np.asarray(values, dtype=float).reshape(-1, 3)
        columns = [None if np.all(np.isnan(table[:, j])) else table[:, j] for j in (1, 2)]
        histories[name] = ConvergenceHistory(table[:, 0], *columns)
    return histories

"""What became of one run of a batch (a row of ``batch_summary.csv``)."""

from __future__ import annotations

import math
from typing import Any

import attrs

#: statuses: finished now; finished earlier with the same inputs (not run again); failed (the
#: message says why); not started because a run it depends on did not finish; stopped by Ctrl-C
OK, SKIPPED, FAILED, NOT_RUN, STOPPED = "ok", "skipped", "failed", "not run", "stopped"
FINISHED = (OK, SKIPPED)


def _number(value: Any) -> float | None:
    try:
        number = float(value)
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def _count(value: Any) -> int | None:
    try:
        return None if value is None else int(value)
    except (TypeError, ValueError):
        return None


@attrs.frozen
class RunOutcome:
    """One run's status and headline figures.

    ``objective``: the solver's final cost (a Design Optimization's design goal);
    ``initial_objective``: the cost at its starting point (for a warm-started run, the
    parent's solution) and ``objective_change`` the difference; ``tracking_rms``: RMS over the
    tracked coordinates of modeled minus tracked positions (deg for rotations; for a run
    warm-started from its parent and tracking it, how far the motion moved); ``wall_time``
    (s) of the run on its worker and ``cpu_time`` (s), the CPU time its worker process used
    meanwhile (the run's threads and the worker's own bookkeeping); ``attempts``: 2 when a
    worker died while running it and it ran again.
    """

    name: str
    status: str
    message: str = ""
    ipopt_status: str = attrs.field(default="", converter=str)
    iterations: int | None = attrs.field(default=None, converter=_count)
    objective: float | None = attrs.field(default=None, converter=_number)
    initial_objective: float | None = attrs.field(default=None, converter=_number)
    tracking_rms: float | None = attrs.field(default=None, converter=_number)
    wall_time: float | None = attrs.field(default=None, converter=_number)
    cpu_time: float | None = attrs.field(default=None, converter=_number)
    worker: str = ""
    attempts: int = 1
    warnings: tuple[str, ...] = ()

    @property
    def objective_change(self) -> float | None:
        if self.objective is None or self.initial_objective is None:
            return None
        return self.objective - self.initial_objective

    def to_json(self) -> dict[str, Any]:
        return attrs.asdict(self)

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> RunOutcome:
        names = {f.name for f in attrs.fields(cls)}
        values = {k: v for k, v in data.items() if k in names}
        values["warnings"] = tuple(values.get("warnings", ()))
        return cls(**values)

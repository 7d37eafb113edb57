"""What a Tracking, Verification or Design Optimization run produced (:class:`TreatmentRun`):
made by :mod:`nmsm.tools.treatment.run`, read by its console summary
(:mod:`nmsm.tools.treatment.summary`), the comparisons and callers of ``run_settings``."""

from __future__ import annotations

from pathlib import Path

import attrs

from nmsm.core.problem import Solution
from nmsm.tools.treatment.solution import TreatmentSolution
from nmsm.tools.treatment.tool import Prepared


@attrs.define
class TreatmentRun:
    """What a run produced."""

    prepared: Prepared
    solution: Solution
    result: TreatmentSolution
    summary: str
    initial_cost: float
    results_directory: Path | None
    files: list[Path]
    build_time: float

    @property
    def cost(self) -> float:
        return self.solution.cost

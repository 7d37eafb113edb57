"""What a back end returns from solving an :class:`~nmsm.core.problem.OptimizationProblem`."""

from __future__ import annotations

import attrs
import numpy as np

from nmsm.core.convergence import ConvergenceHistory
from nmsm.core.term import SourceRef


@attrs.frozen
class ConstraintStatus:
    """A constraint block at the solution: worst violation and how many rows are at a bound."""

    name: str
    size: int
    max_violation: float
    n_active: int
    source: SourceRef | None


@attrs.frozen
class Solution:
    """Result of a solve. ``values`` are unscaled, in each variable's shape; ``evaluations``
    counts the residual (and Jacobian) evaluations where the back end reports them."""

    values: dict[str, np.ndarray]
    cost: float
    term_costs: dict[str, float]
    success: bool
    status: str
    iterations: int
    wall_time: float
    backend: str
    x_scaled: np.ndarray
    constraints: tuple[ConstraintStatus, ...] = ()
    history: ConvergenceHistory | None = None
    evaluations: int | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[name]

    def summary(self) -> str:
        lines = [
            f"{self.backend}: {self.status} after {self.iterations} iterations, "
            f"{self.wall_time:.2f} s, cost {self.cost:.6g}"
        ]
        for name, value in self.term_costs.items():
            lines.append(f"  {name:<48s} {value:.6g}")
        bad = [c for c in self.constraints if c.max_violation > 1e-6]
        active = [c for c in self.constraints if c.n_active]
        if self.constraints:
            lines.append(f"  constraints: {len(self.constraints)} blocks, {len(active)} with active bounds, "
                         f"{len(bad)} violated > 1e-6")
            for c in bad:
                lines.append(f"    violated: {c.name} (max {c.max_violation:.3g})")
        return "\n".join(lines)

"""What GCP hands to its cost terms (``nmsm/terms/gcp``).

:class:`GcpContext` holds every foot's :class:`~nmsm.tools.gcp.values.FootValues` and the
design of the task. Terms ask it for raw per-foot quantities; each foot's block is reduced
on its own as ``raw / (e sqrt(len(raw)))`` (as the original's GCP), i.e.
:func:`nmsm.core.reductions.mean_square` per block.

Raw quantities (per foot, ``T`` frames; all modeled minus experimental):

* marker positions/velocities (3, 5T) m, m/s;
* coordinates (7, T) rad/m (rows 0..3 toe angle and hindfoot rotations, 4..6 translations);
* forces, moments and their slopes (3, T) N, N m, N/s, N m/s;
* spring constants (n,) N/m; neighbor deviation (n, T) N/m;
* electrical-center shift (3,) m, plate rotation (1,) rad.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as cs
import numpy as np

from nmsm.core import reductions
from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.neighbors import NeighborOperator
from nmsm.tools.gcp.state import Design
from nmsm.tools.gcp.values import FootValues

#: floor of the periodicity normalization: 0.0175 rad for the 4 angles, 0.001 m for translations
PERIODICITY_FLOOR = np.array([0.0175] * 4 + [0.001] * 3)


def _stack_markers(markers: np.ndarray) -> cs.DM:
    """(T, 5, 3) -> (3, 5T) with frame ``t`` in columns 5t..5t+4."""
    return cs.DM(markers.reshape(-1, 3).T)


class GcpContext:
    """Modeled GCP quantities for the terms (module docstring)."""

    tool = "GCP"

    def __init__(self, feet: Sequence[FootInputs], values: Sequence[FootValues], design: Design,
                 neighbor_standard_deviation: float) -> None:
        self.feet = list(feet)
        self.values = list(values)
        self.design = design
        self.neighbor_standard_deviation = float(neighbor_standard_deviation)
        self._neighbor: dict[int, Any] = {}

    @property
    def n_feet(self) -> int:
        return len(self.feet)

    # ------------------------------------------------------------------ kinematics
    def marker_errors(self, foot: int) -> Any:
        return self.values[foot].markers - _stack_markers(self.feet[foot].markers)

    def marker_velocity_errors(self, foot: int) -> Any:
        return self.values[foot].marker_velocities - _stack_markers(self.feet[foot].marker_velocities)

    def coordinate_errors(self, foot: int, rows: slice) -> Any:
        """Modeled minus experimental foot coordinates ``rows`` (k, T)."""
        return self.values[foot].coordinates[rows, :] - cs.DM(self.feet[foot].coordinates.T[rows, :])

    def periodicity(self, foot: int) -> Any:
        """``(q(t0) - q(tf)) / max(|q_exp(t0) - q_exp(tf)|, floor)`` (7,)."""
        q = self.values[foot].coordinates
        exp = self.feet[foot].coordinates
        scale = np.maximum(np.abs(exp[0] - exp[-1]), PERIODICITY_FLOOR)
        return (q[:, 0] - q[:, -1]) / cs.DM(scale)

    # ------------------------------------------------------------------ ground reactions
    def force_errors(self, foot: int, rows: Sequence[int]) -> Any:
        v = self.values[foot]
        return v.forces[list(rows), :] - v.experimental_forces[list(rows), :]

    def force_slope_errors(self, foot: int, rows: Sequence[int]) -> Any:
        v, f = self.values[foot], self.feet[foot]
        modeled = cs.mtimes(v.forces[list(rows), :], cs.DM(f.slope_modeled.T))
        experimental = cs.mtimes(v.experimental_forces[list(rows), :], cs.DM(f.slope_experimental.T))
        return modeled - experimental

    def moment_errors(self, foot: int) -> Any:
        v = self.values[foot]
        return v.moments - v.experimental_moments

    def moment_slope_errors(self, foot: int) -> Any:
        v, f = self.values[foot], self.feet[foot]
        return (cs.mtimes(v.moments, cs.DM(f.slope_modeled.T))
                - cs.mtimes(v.experimental_moments, cs.DM(f.slope_experimental.T)))

    # ------------------------------------------------------------------ springs and plates
    def spring_constants_minus_mean(self) -> Any:
        """``K - mean(K)`` (n,) N/m."""
        k = self.design.spring_constants
        return k - cs.sum1(k) / k.shape[0]

    def neighbor_deviation(self, foot: int) -> Any:
        """``K_j - sum_k w_jk K_k / sum_k w_jk`` (n, T), ``w_jk = exp(-d_jk^2 / (2 sigma^2))``
        over the other springs ``k``, ``d`` their 3-D distance in each frame
        (:class:`~nmsm.tools.gcp.neighbors.NeighborOperator`)."""
        if foot not in self._neighbor:
            f = self.feet[foot]
            operator = NeighborOperator(f.foot, f.springs, self.neighbor_standard_deviation)
            self._neighbor[foot] = operator.deviation(self.values[foot].coordinates[0, :],
                                                      self.design.spring_constants)
        return self._neighbor[foot]

    def electrical_center_shift(self, foot: int) -> Any:
        return self.design.electrical_center_shifts[foot]

    def plate_rotation(self, foot: int) -> Any:
        return self.design.plate_rotations[foot]

    # ------------------------------------------------------------------ reductions
    def reduce_cost(self, term: Any, blocks: Any) -> Any:
        """Each foot's block reduced to ``z / sqrt(len(z))``, stacked."""
        parts = [reductions.mean_square(cs.vec(block)) for block in blocks]
        return cs.vertcat(*parts) if parts else cs.DM(0, 1)

    def reduce_constraint(self, term: Any, value: Any) -> tuple[Any, Any, Any]:
        raise term.error("GCP has no constraint terms", expected="cost terms only")


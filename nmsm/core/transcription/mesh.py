"""The collocation mesh in normalized time ``s = t / t_f in [0, 1]``.

A mesh has ``M`` intervals (fractions of the phase summing to 1) with ``n_i`` LGR
collocation points each (GPOPS-II's ``setup_mesh_phase_intervals`` and
``setup_mesh_phase_colpoints_per_Interval``). ``K = sum(n_i)`` collocation points plus the
phase end give ``K + 1`` *nodes*; interval ``i``'s last node is interval ``i + 1``'s first.

Named grids (row sets of the transcribed trajectory):

``nodes``        all ``K + 1`` nodes (collocation points then the phase end), as written to
                 the ``.sto`` outputs;
``collocation``  the ``K`` collocation points (path constraints, cost integrands);
``initial``      the first node; ``final`` the phase end.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import numpy as np

from nmsm.core.transcription.radau import lagrange_basis_at, radau_rule

GRIDS = ("nodes", "collocation", "initial", "final")


@attrs.frozen
class Mesh:
    """Interval fractions (sum 1) and collocation points per interval."""

    fractions: tuple[float, ...]
    points: tuple[int, ...]

    def __attrs_post_init__(self) -> None:
        if len(self.fractions) != len(self.points) or not self.fractions:
            raise ValueError("a mesh needs one point count per interval and at least one interval")
        if any(f <= 0 for f in self.fractions) or abs(sum(self.fractions) - 1.0) > 1e-12:
            raise ValueError(f"interval fractions must be positive and sum to 1, got {self.fractions}")
        if any(n < 1 for n in self.points):
            raise ValueError(f"every interval needs at least 1 collocation point, got {self.points}")

    @classmethod
    def uniform(cls, intervals: int, points_per_interval: int) -> Mesh:
        """``intervals`` equal intervals with ``points_per_interval`` LGR points each."""
        if intervals < 1 or points_per_interval < 1:
            raise ValueError(
                f"mesh needs >= 1 interval and >= 1 point per interval, got {intervals} x {points_per_interval}"
            )
        return cls(tuple([1.0 / intervals] * intervals), tuple([points_per_interval] * intervals))

    # ---- sizes and indices ---------------------------------------------------------------
    @property
    def n_intervals(self) -> int:
        return len(self.points)

    @property
    def n_collocation(self) -> int:
        """``K``, the number of collocation points."""
        return int(sum(self.points))

    @property
    def n_nodes(self) -> int:
        """``K + 1``."""
        return self.n_collocation + 1

    @property
    def interval_starts(self) -> np.ndarray:
        """(M + 1,) normalized times of the interval boundaries."""
        return np.concatenate([[0.0], np.cumsum(self.fractions)])

    def interval_node_indices(self, i: int) -> np.ndarray:
        """Node indices (n_i + 1) of interval ``i``, end point included."""
        start = int(sum(self.points[:i]))
        return np.arange(start, start + self.points[i] + 1)

    def rows(self, grid: str) -> np.ndarray:
        """Node indices making up ``grid`` (see module docstring)."""
        if grid == "nodes":
            return np.arange(self.n_nodes)
        if grid == "collocation":
            return np.arange(self.n_collocation)
        if grid == "initial":
            return np.array([0])
        if grid == "final":
            return np.array([self.n_collocation])
        raise ValueError(f"unknown grid '{grid}' (expected one of {', '.join(GRIDS)})")

    # ---- times and quadrature -------------------------------------------------------------
    @property
    def node_times(self) -> np.ndarray:
        """(K + 1,) normalized times of all nodes in [0, 1]."""
        out = np.empty(self.n_nodes)
        starts = self.interval_starts
        for i, n in enumerate(self.points):
            rule = radau_rule(n)
            idx = self.interval_node_indices(i)
            out[idx] = starts[i] + 0.5 * (rule.nodes + 1.0) * self.fractions[i]
        out[-1] = 1.0
        return out

    def times(self, grid: str) -> np.ndarray:
        return self.node_times[self.rows(grid)]

    @property
    def quadrature_weights(self) -> np.ndarray:
        """(K,) weights of the collocation points for ``integral_0^1 g(s) ds`` (sum 1)."""
        out = np.empty(self.n_collocation)
        for i, n in enumerate(self.points):
            rule = radau_rule(n)
            idx = self.interval_node_indices(i)[:-1]
            out[idx] = 0.5 * self.fractions[i] * rule.weights
        return out

    # ---- interpolation --------------------------------------------------------------------
    def final_extrapolation(self) -> np.ndarray:
        """(K,) row mapping collocation values to the phase-end value of the last interval's
        degree ``n - 1`` interpolating polynomial (how controls are defined at ``t_f``)."""
        row = np.zeros(self.n_collocation)
        last = self.n_intervals - 1
        idx = self.interval_node_indices(last)[:-1]
        row[idx] = radau_rule(self.points[last]).extrapolate
        return row

    def _interval_of(self, s: np.ndarray) -> np.ndarray:
        starts = self.interval_starts
        return np.clip(np.searchsorted(starts, s, side="right") - 1, 0, self.n_intervals - 1)

    def state_interpolation(self, s: Sequence[float] | np.ndarray) -> np.ndarray:
        """(len(s), K + 1) matrix interpolating node values (states) at normalized times ``s``
        with each interval's degree ``n_i`` Lagrange polynomial."""
        return self._interpolation(s, self.n_nodes, lambda i: (self.interval_node_indices(i),
                                                               radau_rule(self.points[i]).nodes))

    def control_interpolation(self, s: Sequence[float] | np.ndarray) -> np.ndarray:
        """(len(s), K) matrix interpolating collocation values (controls) at ``s`` with each
        interval's degree ``n_i - 1`` Lagrange polynomial on its collocation points."""
        return self._interpolation(s, self.n_collocation, lambda i: (self.interval_node_indices(i)[:-1],
                                                                     radau_rule(self.points[i]).collocation))

    def _interpolation(self, s: Sequence[float] | np.ndarray, n_columns: int, basis: Any) -> np.ndarray:
        """(len(s), n_columns) Lagrange interpolation at ``s``; ``basis(i)`` gives interval
        ``i``'s (columns, interpolation points on [-1, 1])."""
        s = np.atleast_1d(np.asarray(s, dtype=float))
        out = np.zeros((s.size, n_columns))
        which = self._interval_of(s)
        starts = self.interval_starts
        for i in np.unique(which):
            sel = which == i
            tau = 2.0 * (s[sel] - starts[i]) / self.fractions[i] - 1.0
            columns, points = basis(i)
            out[np.ix_(np.flatnonzero(sel), columns)] = lagrange_basis_at(points, tau)
        return out

"""Legendre-Gauss-Radau (LGR) direct collocation, as GPOPS-II's Radau pseudospectral method.

Variables: states at the ``K + 1`` mesh nodes ``(K + 1, nx)``, controls at the ``K``
collocation points ``(K, nu)``, and ``t_f`` when free. Defects per interval ``i``::

    D_i X_i = (h_i / 2) * t_f * f(X_k, U_k, p)      at its n_i collocation points

(``h_i`` = interval fraction of the normalized phase), divided by each state's scale so
every defect row is O(1). Controls at the phase end are the last interval's interpolating
polynomial extrapolated to ``s = 1`` (so terminal terms see real end controls, not a
placeholder). Integrals use the LGR quadrature of the collocation points.
"""

from __future__ import annotations

from typing import Any

import attrs
import casadi as cs
import numpy as np
import scipy.sparse

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.row_map import map_rows
from nmsm.core.transcription.base import Phase, Trajectory, Transcription
from nmsm.core.transcription.radau import radau_rule


def _block_scale(lower: np.ndarray, upper: np.ndarray, scale: np.ndarray | None) -> np.ndarray:
    if scale is not None:
        return np.asarray(scale, dtype=float)
    finite = np.isfinite(lower) & np.isfinite(upper) & (upper > lower)
    out = np.ones_like(lower)
    out[finite] = (upper - lower)[finite]
    return out


def _block_offset(lower: np.ndarray, upper: np.ndarray, offset: np.ndarray | None) -> np.ndarray:
    if offset is not None:
        return np.asarray(offset, dtype=float)
    finite = np.isfinite(lower) & np.isfinite(upper) & (upper > lower)
    out = np.zeros_like(lower)
    out[finite] = 0.5 * (upper + lower)[finite]
    return out


def differentiation_operator(phase: Phase) -> scipy.sparse.csr_matrix:
    """(K, K + 1) sparse matrix stacking each interval's LGR differentiation matrix, scaled
    to normalized time ``s`` (``d/ds = (2 / h_i) d/dtau``)."""
    mesh = phase.mesh
    rows, cols, vals = [], [], []
    for i, n in enumerate(mesh.points):
        rule = radau_rule(n)
        idx = mesh.interval_node_indices(i)
        D = rule.derivative * (2.0 / mesh.fractions[i])
        r, c = np.nonzero(np.ones_like(D, dtype=bool))
        rows.append(idx[:-1][r])
        cols.append(idx[c])
        vals.append(D[r, c])
    return scipy.sparse.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(mesh.n_collocation, mesh.n_nodes),
    )


def _dm_sparse(mat: scipy.sparse.spmatrix) -> cs.DM:
    return cs.DM(scipy.sparse.csc_matrix(mat))


@attrs.define
class RadauTrajectory(Trajectory):
    """LGR-transcribed phase (see module docstring)."""

    phase: Phase
    problem: OptimizationProblem
    X: cs.MX  # (K + 1, nx)
    U: cs.MX  # (K, nu)
    tf: cs.MX  # scalar
    state_var: str
    control_var: str
    final_time_var: str | None

    @property
    def final_time(self) -> cs.MX:
        return self.tf

    def grid_size(self, grid: str) -> int:
        return self.phase.mesh.rows(grid).size

    def normalized_times(self, grid: str) -> np.ndarray:
        return self.phase.mesh.times(grid)

    def states(self, grid: str) -> cs.MX:
        mesh = self.phase.mesh
        if grid == "nodes":
            return self.X
        if grid == "collocation":
            return self.X[: mesh.n_collocation, :]
        if grid == "initial":
            return self.X[0, :]
        if grid == "final":
            return self.X[mesh.n_collocation, :]
        mesh.rows(grid)  # raises for unknown grids
        raise AssertionError

    def _final_controls(self) -> cs.MX:
        return cs.DM(self.phase.mesh.final_extrapolation()).T @ self.U

    def controls(self, grid: str) -> cs.MX:
        if grid == "collocation":
            return self.U
        if grid == "nodes":
            return cs.vertcat(self.U, self._final_controls())
        if grid == "initial":
            return self.U[0, :]
        if grid == "final":
            return self._final_controls()
        self.phase.mesh.rows(grid)
        raise AssertionError

    @property
    def integration_grid(self) -> str:
        return "collocation"

    @property
    def quadrature_weights(self) -> np.ndarray:
        return self.phase.mesh.quadrature_weights

    def _numeric(self, solution: Solution | dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, float]:
        values = solution.values if isinstance(solution, Solution) else solution
        X = np.asarray(values[self.state_var])
        U = np.asarray(values[self.control_var]) if self.control_var in values else np.zeros((X.shape[0] - 1, 0))
        if self.final_time_var is not None:
            tf = float(np.asarray(values[self.final_time_var]).ravel()[0])
        else:
            tf = self.phase.final_time.guess
        return X, U, tf

    def sample(self, solution: Solution | dict[str, np.ndarray], grid: str | np.ndarray = "nodes") -> dict[str, Any]:
        mesh = self.phase.mesh
        X, U, tf = self._numeric(solution)
        if isinstance(grid, str):
            rows = mesh.rows(grid)
            s = mesh.node_times[rows]
            states = X[rows]
            U_nodes = np.vstack([U, mesh.final_extrapolation() @ U]) if U.shape[1] else np.zeros((mesh.n_nodes, 0))
            controls = U_nodes[rows]
        else:
            s = np.clip(np.asarray(grid, dtype=float).ravel(), 0.0, 1.0)
            states = mesh.state_interpolation(s) @ X
            controls = mesh.control_interpolation(s) @ U if U.shape[1] else np.zeros((s.size, 0))
        return {"time": s * tf, "normalized_time": s, "states": states, "controls": controls, "final_time": tf}


@attrs.define
class RadauCollocation(Transcription):
    """LGR collocation of any degree on the phase's mesh.

    ``parallel``: threads used to map the per-point dynamics (1 = serial).
    """

    parallel: int = 1
    name: str = "radau"

    def transcribe(self, phase: Phase, problem: OptimizationProblem, *, prefix: str = "") -> RadauTrajectory:
        mesh = phase.mesh
        sb, cb = phase.states, phase.controls
        nx, nu = len(sb.names), len(cb.names)
        s_scale = _block_scale(sb.lower, sb.upper, sb.scale)
        s_off = _block_offset(sb.lower, sb.upper, sb.offset)
        state_var = f"{prefix}states"
        X = problem.variable(
            state_var, sb.guess, sb.lower[None, :], sb.upper[None, :],
            scale=s_scale[None, :], offset=s_off[None, :], shape=(mesh.n_nodes, nx),
        )
        control_var = f"{prefix}controls"
        if nu:
            c_scale = _block_scale(cb.lower, cb.upper, cb.scale)
            c_off = _block_offset(cb.lower, cb.upper, cb.offset)
            U = problem.variable(
                control_var, cb.guess, cb.lower[None, :], cb.upper[None, :],
                scale=c_scale[None, :], offset=c_off[None, :], shape=(mesh.n_collocation, nu),
            )
        else:
            U = cs.MX(mesh.n_collocation, 0)
        ft = phase.final_time
        final_time_var = None
        if ft.is_free:
            final_time_var = f"{prefix}final_time"
            tf = problem.variable(final_time_var, ft.guess, ft.lower, ft.upper)
        else:
            tf = cs.MX(ft.guess)
        # defects: D X = (h/2 in s -> already in D) t_f f(X_k, U_k, p)
        D = _dm_sparse(differentiation_operator(phase))
        Xc = X[: mesh.n_collocation, :]
        p = phase.parameters
        p_row = cs.MX(p).T if p.numel() else cs.MX(1, 0)
        (F,) = map_rows(phase.dynamics, Xc, U, p_row, parallel=self.parallel)
        defects = (D @ X - tf * F) / cs.repmat(cs.DM(s_scale).T, mesh.n_collocation, 1)
        problem.add_constraint(f"{prefix}dynamics_defects", defects, 0.0, 0.0)
        return RadauTrajectory(phase, problem, X, U, tf, state_var, control_var if nu else "", final_time_var)

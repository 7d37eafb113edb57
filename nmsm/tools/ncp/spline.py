"""Synergy commands from spline nodes: a constant interpolation matrix.

NCP describes each synergy command of a trial by ``n_nodes`` values at evenly spaced
points of the normalized cycle (0-100 %) and interpolates them with a not-a-knot cubic
spline at the ``n_points`` data frames. The interpolant is linear in the
node values, so it is one constant matrix ``B`` (n_points, n_nodes):

    commands (n_points, n_synergies) = B @ nodes (n_nodes, n_synergies)

which keeps the optimization problem polynomial (exact, cheap derivatives).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.interpolate import CubicSpline

#: number of command nodes per synergy and trial
DEFAULT_NODE_COUNT = 21


@lru_cache(maxsize=32)
def _interpolation_matrix(n_nodes: int, n_points: int) -> np.ndarray:
    node_x = np.linspace(0.0, 100.0, n_nodes)
    point_x = np.linspace(0.0, 100.0, n_points)
    if n_nodes < 4:
        raise ValueError(f"a not-a-knot cubic spline needs at least 4 nodes, got {n_nodes}")
    basis = CubicSpline(node_x, np.eye(n_nodes), axis=0, bc_type="not-a-knot")(point_x)
    basis.setflags(write=False)
    return basis


def interpolation_matrix(n_nodes: int, n_points: int) -> np.ndarray:
    """``B`` (n_points, n_nodes): not-a-knot cubic interpolation from nodes to frames.

    Nodes sit at ``linspace(0, 100, n_nodes)`` percent of the cycle and frames at
    ``linspace(0, 100, n_points)``; row ``p`` holds the weights of every node at frame ``p``.
    The returned array is read-only (cached).
    """
    return _interpolation_matrix(int(n_nodes), int(n_points))


def commands_from_nodes(nodes: np.ndarray, n_points: int) -> np.ndarray:
    """Commands (n_points, n_synergies) from node values (n_nodes, n_synergies)."""
    nodes = np.asarray(nodes, dtype=float)
    return interpolation_matrix(nodes.shape[0], n_points) @ nodes


def nodes_from_commands(commands: np.ndarray, n_nodes: int = DEFAULT_NODE_COUNT) -> np.ndarray:
    """Least-squares node values (n_nodes, n_synergies) reproducing ``commands`` (n_points, n_synergies)."""
    commands = np.asarray(commands, dtype=float)
    basis = interpolation_matrix(n_nodes, commands.shape[0])
    nodes, *_ = np.linalg.lstsq(basis, commands, rcond=None)
    return nodes

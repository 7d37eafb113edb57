"""The ``neighbor_spring_constant`` deviation, computed from the toe angle.

Per frame ``t`` and spring ``j``::

    dev_jt = K_j - sum_k w_jkt K_k / sum_k w_jkt,   w_jkt = exp(-d_jkt^2 / (2 sigma^2)), k != j

with ``d_jkt`` the 3-D distance of springs ``j`` and ``k`` in frame ``t``. Springs on the
same body keep their distance, so those weights are constants ``W0``; a hindfoot-toes pair's
distance depends only on the toe angle ``theta_t``. Hence, exactly,

    W(theta) = W0 + [[0, C(theta)], [C(theta)^T, 0]]   (hindfoot rows/columns first)

and the numerator ``W(theta) K`` is ``W0 K`` plus the cross block times ``K`` — built with
matrix products so that derivatives with respect to ``K`` stay cheap over many frames.
"""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np

from nmsm.tools.gcp.foot_model import FootModel
from nmsm.tools.gcp.spring_grid import SpringLayout


class NeighborOperator:
    """``dev(theta (1, T), K (n,)) -> (n, T)`` for one foot's springs (module docstring)."""

    def __init__(self, foot: FootModel, springs: SpringLayout, sigma: float) -> None:
        self.n = springs.n_springs
        self.sigma = float(sigma)
        bodies = np.array(springs.bodies)
        self.hind = np.flatnonzero(bodies == foot.hindfoot_body)
        self.toes = np.flatnonzero(bodies == foot.toes_body)
        locations = springs.locations
        self.w0 = np.zeros((self.n, self.n))
        for group in (self.hind, self.toes):
            p = locations[group]
            d2 = ((p[:, None, :] - p[None, :, :]) ** 2).sum(axis=2)
            w = np.exp(-d2 / (2.0 * self.sigma**2))
            np.fill_diagonal(w, 0.0)
            self.w0[np.ix_(group, group)] = w
        theta = cs.SX.sym("theta")
        rotation, origin = foot.toes_pose_in_hindfoot(theta)
        hind = cs.DM(locations[self.hind].T)  # (3, nh) in the hindfoot frame
        toes = cs.repmat(origin, 1, self.toes.size) + cs.mtimes(rotation, cs.DM(locations[self.toes].T))
        cross = []
        for k in range(self.toes.size):
            d2 = cs.sum1((hind - cs.repmat(toes[:, k], 1, self.hind.size)) ** 2)
            cross.append(cs.exp(-d2 / (2.0 * self.sigma**2)).T)
        block = cs.horzcat(*cross) if cross else cs.SX(self.hind.size, 0)  # (nh, nt)
        self.cross_function = cs.Function("neighbor_cross", [theta],
                                          [cs.vec(block), cs.sum2(block), cs.sum1(block).T])

    def deviation(self, theta: Any, spring_constants: Any) -> Any:
        """Deviations (n, T) for toe angles ``theta`` (1, T) rad and ``spring_constants`` (n,)."""
        frames = theta.shape[1]
        k = cs.reshape(spring_constants, self.n, 1)
        own = cs.mtimes(cs.DM(self.w0), k)
        own_sum = self.w0.sum(axis=1)
        numerator = cs.repmat(own, 1, frames)
        denominator = cs.repmat(cs.DM(own_sum), 1, frames)
        nh, nt = self.hind.size, self.toes.size
        if nh and nt:
            block, hind_sum, toes_sum = self.cross_function.map(frames, "serial")(theta)
            k_hind = k[self.hind.tolist()]
            k_toes = k[self.toes.tolist()]
            to_hind = cs.mtimes(cs.kron(k_toes.T, cs.DM.eye(nh)), block)  # (nh, T): C(theta) K_toes
            to_toes = cs.mtimes(cs.kron(cs.DM.eye(nt), k_hind.T), block)  # (nt, T): C^T K_hind
            scatter_h = _selector(self.hind, self.n)
            scatter_t = _selector(self.toes, self.n)
            numerator = numerator + cs.mtimes(scatter_h, to_hind) + cs.mtimes(scatter_t, to_toes)
            denominator = denominator + cs.mtimes(scatter_h, hind_sum) + cs.mtimes(scatter_t, toes_sum)
        return cs.repmat(k, 1, frames) - numerator / denominator


def _selector(rows: np.ndarray, n: int) -> cs.DM:
    """Sparse (n, len(rows)) matrix placing a block's rows at ``rows``."""
    return cs.DM.triplet(rows.tolist(), list(range(rows.size)), [1.0] * rows.size, n, rows.size)

"""Jacobians of least-squares residuals, by structure, with the linear algebra a
Levenberg-Marquardt step needs (:mod:`nmsm.core.backends.levenberg_marquardt`).

A :class:`~nmsm.core.residual_problem.ResidualProblem` returns its Jacobian as one of these:

* :class:`DenseJacobian` (numpy; small problems, e.g. one inverse-kinematics frame);
* :class:`SparseJacobian` (scipy sparse; SuperLU on the damped normal matrix);
* :class:`BlockArrowJacobian` (residual blocks ``r_f`` that depend on their own variables
  ``q_f`` and on shared ones ``p``: ``x = [q_1, ..., q_F, p]``), solved by the Schur
  complement on the shared variables in time linear in the number of blocks.
"""

from __future__ import annotations

from typing import Any, Protocol

import attrs
import numpy as np
import scipy.sparse
import scipy.sparse.linalg


class Jacobian(Protocol):
    """What the algorithm needs from a Jacobian ``J`` (m x n)."""

    def gradient(self, r: np.ndarray) -> np.ndarray:
        """``J^T r`` (n,)."""

    def normal_diagonal(self) -> np.ndarray:
        """``diag(J^T J)`` (n,)."""

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        """``s`` with ``(J^T J + mu diag(diag))_ff s_f = -g_f`` and ``s = 0`` off ``free``."""

    def product(self, s: np.ndarray) -> np.ndarray:
        """``J s`` (m,)."""

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        """``|J s|^2``."""


class _MatrixProducts:
    """``J s`` and ``|J s|²`` of a Jacobian held as ``matrix`` (numpy or scipy sparse)."""

    matrix: Any

    def product(self, s: np.ndarray) -> np.ndarray:
        return np.asarray(self.matrix @ s).ravel()

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        v = self.product(s)
        return float(v @ v)


@attrs.frozen
class DenseJacobian(_MatrixProducts):
    """A numpy Jacobian ``(m, n)``."""

    matrix: np.ndarray

    def gradient(self, r: np.ndarray) -> np.ndarray:
        return self.matrix.T @ r

    def normal_diagonal(self) -> np.ndarray:
        return np.einsum("ij,ij->j", self.matrix, self.matrix)

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        idx = np.flatnonzero(free)
        step = np.zeros_like(g)
        if idx.size == 0:
            return step
        j = self.matrix[:, idx]
        a = j.T @ j
        a[np.diag_indices_from(a)] += mu * diag[idx]
        try:
            step[idx] = -np.linalg.solve(a, g[idx])
        except np.linalg.LinAlgError:
            step[idx] = -np.linalg.lstsq(a, g[idx], rcond=None)[0]
        return step



@attrs.frozen
class SparseJacobian(_MatrixProducts):
    """A scipy sparse Jacobian ``(m, n)``."""

    matrix: scipy.sparse.csc_matrix

    def gradient(self, r: np.ndarray) -> np.ndarray:
        return np.asarray(self.matrix.T @ r).ravel()

    def normal_diagonal(self) -> np.ndarray:
        return np.asarray(self.matrix.multiply(self.matrix).sum(axis=0)).ravel()

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        idx = np.flatnonzero(free)
        step = np.zeros_like(g)
        if idx.size == 0:
            return step
        j = self.matrix[:, idx]
        a = (j.T @ j).tocsc() + scipy.sparse.diags(mu * diag[idx], format="csc")
        step[idx] = -scipy.sparse.linalg.splu(a, permc_spec="COLAMD").solve(g[idx])
        return step



@attrs.frozen
class BlockArrowJacobian:
    """Jacobian of residuals ``r = [r_1; ...; r_F]`` (``r_f``: m each) in ``x = [q_1 .. q_F, p]``
    where ``r_f`` depends on ``q_f`` (n each) and ``p`` (k) only.

    ``dq`` ``(F, m, n)`` = dr_f/dq_f; ``dp`` ``(F, m, k)`` = dr_f/dp.
    """

    dq: np.ndarray = attrs.field(converter=np.ascontiguousarray)
    dp: np.ndarray = attrs.field(converter=np.ascontiguousarray)

    @property
    def shape(self) -> tuple[int, int, int, int]:
        f, m, n = self.dq.shape
        return f, m, n, self.dp.shape[2]

    def gradient(self, r: np.ndarray) -> np.ndarray:
        f, m, n, k = self.shape
        rr = r.reshape(f, m)
        return np.concatenate([np.einsum("fmn,fm->fn", self.dq, rr).ravel(), np.einsum("fmk,fm->k", self.dp, rr)])

    def normal_diagonal(self) -> np.ndarray:
        return np.concatenate([np.einsum("fmn,fmn->fn", self.dq, self.dq).ravel(),
                               np.einsum("fmk,fmk->k", self.dp, self.dp)])

    def damped_step(self, g: np.ndarray, free: np.ndarray, mu: float, diag: np.ndarray) -> np.ndarray:
        f, m, n, k = self.shape
        free_q = free[: f * n].reshape(f, n).astype(float)
        free_p = free[f * n:].astype(float)
        # stacked small products (one per frame): BLAS stays single-threaded at these sizes,
        # which is much faster than one large threaded product on a busy machine
        dq = self.dq * free_q[:, None, :]
        dp = self.dp * free_p[None, None, :]
        dq_t = dq.transpose(0, 2, 1)
        a = dq_t @ dq
        b = dq_t @ dp
        c = (dp.transpose(0, 2, 1) @ dp).sum(axis=0)
        dq_diag = (mu * diag[: f * n].reshape(f, n)) * free_q + (1.0 - free_q)
        a[:, np.arange(n), np.arange(n)] += dq_diag
        c[np.arange(k), np.arange(k)] += mu * diag[f * n:] * free_p + (1.0 - free_p)
        gq = g[: f * n].reshape(f, n) * free_q
        gp = g[f * n:] * free_p
        if k == 0:
            return -np.linalg.solve(a, gq[:, :, None])[:, :, 0].ravel()
        solved = np.linalg.solve(a, np.concatenate([b, gq[:, :, None]], axis=2))
        x_b, y = solved[:, :, :k], solved[:, :, k]
        b_t = b.transpose(0, 2, 1)
        schur = c - (b_t @ x_b).sum(axis=0)
        rhs = -gp + (b_t @ y[:, :, None]).sum(axis=0)[:, 0]
        step_p = np.linalg.solve(schur, rhs)
        step_q = -(y + x_b @ step_p)
        return np.concatenate([step_q.ravel(), step_p]) * free

    def product(self, s: np.ndarray) -> np.ndarray:
        f, m, n, k = self.shape
        v = np.einsum("fmn,fn->fm", self.dq, s[: f * n].reshape(f, n)) + np.einsum("fmk,k->fm", self.dp, s[f * n:])
        return v.ravel()

    def squared_norm_of_product(self, s: np.ndarray) -> float:
        v = self.product(s)
        return float(v @ v)

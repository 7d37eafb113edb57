"""CasADi sparse matrices as scipy CSC matrices (the least-squares paths' Jacobians)."""

from __future__ import annotations

import casadi as cs
import numpy as np
import scipy.sparse


def dm_to_csc(value: cs.DM) -> scipy.sparse.csc_matrix:
    """A sparse DM as a scipy CSC matrix (same pattern, explicit zeros kept)."""
    sp = value.sparsity()
    return scipy.sparse.csc_matrix((np.asarray(value.nonzeros(), dtype=float), np.asarray(sp.row()),
                                    np.asarray(sp.colind())), shape=(sp.size1(), sp.size2()))


class SparseOutput:
    """A CasADi Function of ``(x, p)`` whose one output is a sparse matrix, evaluated
    through CasADi's buffer interface straight into a scipy CSC matrix: the pattern is read
    once, and no DM is made per call (for GCP's Jacobians, converting the DM and its row and
    column lists took about as long as computing them)."""

    def __init__(self, function: cs.Function) -> None:
        sp = function.sparsity_out(0)
        self.shape = (sp.size1(), sp.size2())
        self.indices = np.asarray(sp.row(), dtype=np.int64)
        self.indptr = np.asarray(sp.colind(), dtype=np.int64)
        self._x = np.zeros(function.nnz_in(0))
        self._p = np.zeros(function.nnz_in(1))
        self._out = np.zeros(sp.nnz())
        self._buffer, self._evaluate = function.buffer()
        self._buffer.set_arg(0, memoryview(self._x))
        self._buffer.set_arg(1, memoryview(self._p))
        self._buffer.set_res(0, memoryview(self._out))

    def __call__(self, x: np.ndarray, p: np.ndarray) -> scipy.sparse.csc_matrix:
        """The output at ``(x, p)`` (dense vectors of the Function's input sizes)."""
        self._x[:] = x
        self._p[:] = p
        self._evaluate()
        return scipy.sparse.csc_matrix((self._out.copy(), self.indices, self.indptr), shape=self.shape)

"""Calling a CasADi Function on numpy arrays without DM conversions.

Converting large outputs (a mapped Jacobian of half a million entries) to numpy through
``DM`` costs more than evaluating them. :class:`DenseEvaluator` binds numpy buffers to the
function once (``Function.buffer``) and scatters each output's structural nonzeros into a
dense array.

Inputs are dense and read column-major: an input of shape ``(r, c)`` is passed as a numpy
array whose C-order flattening lists column after column, e.g. ``q`` ``(n, F)`` is passed as
the ``(F, n)`` array of frames. Outputs come back dense, shape ``(size1, size2)``.
"""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np


class DenseEvaluator:
    """``evaluator(*inputs) -> [dense outputs]`` for a CasADi Function (see module docstring)."""

    def __init__(self, function: cs.Function) -> None:
        self.function = function
        self._buffer, self._call = function.buffer()
        self._inputs = [np.zeros(function.nnz_in(i)) for i in range(function.n_in())]
        for i in range(function.n_in()):
            if function.nnz_in(i) != function.numel_in(i):
                raise ValueError(f"input {i} of {function.name()} is not dense")
        self._outputs = [np.zeros(function.nnz_out(i)) for i in range(function.n_out())]
        for i, array in enumerate(self._inputs):
            self._buffer.set_arg(i, memoryview(array))
        for i, array in enumerate(self._outputs):
            self._buffer.set_res(i, memoryview(array))
        self._scatter = []
        for i in range(function.n_out()):
            sp = function.sparsity_out(i)
            rows = np.asarray(sp.row(), dtype=np.int64)
            colind = np.asarray(sp.colind(), dtype=np.int64)
            cols = np.repeat(np.arange(sp.size2()), np.diff(colind))
            self._scatter.append((sp.size1(), sp.size2(), rows, cols))

    def __call__(self, *inputs: Any) -> list[np.ndarray]:
        if len(inputs) != len(self._inputs):
            raise ValueError(f"{self.function.name()} takes {len(self._inputs)} inputs, got {len(inputs)}")
        for target, value in zip(self._inputs, inputs):
            flat = np.asarray(value, dtype=float).reshape(-1)
            if flat.size != target.size:
                raise ValueError(f"{self.function.name()}: input of {flat.size} values, expected {target.size}")
            target[:] = flat
        self._call()
        out = []
        for values, (n_rows, n_cols, rows, cols) in zip(self._outputs, self._scatter):
            dense = np.zeros((n_rows, n_cols))
            dense[rows, cols] = values
            out.append(dense)
        return out

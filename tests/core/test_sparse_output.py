"""CasADi sparse outputs as scipy CSC matrices (nmsm.core.backends.sparse)."""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.core.backends.sparse import SparseOutput, dm_to_csc


def _jacobian_function(n_p: int) -> cs.Function:
    x = cs.MX.sym("x", 6)
    p = cs.MX.sym("p", n_p)
    scale = cs.sum1(p) if n_p else 1.0
    r = cs.vertcat(cs.sin(x[:4]) * x[1:5] * scale, cs.cumsum(x)[-1], x[5] ** 3)
    return cs.Function("residual_jacobian", [x, p], [cs.jacobian(r, x)])


def test_sparse_output_equals_the_dm_and_is_fresh_each_call():
    f = _jacobian_function(3)
    evaluate = SparseOutput(f)
    rng = np.random.default_rng(1)
    first_x, p = rng.standard_normal(6), rng.standard_normal(3)
    first = evaluate(first_x, p)
    np.testing.assert_array_equal(first.toarray(), f(first_x, p).full())
    assert first.nnz == f.sparsity_out(0).nnz()
    kept = first.toarray().copy()
    second_x = rng.standard_normal(6)
    second = evaluate(second_x, p)
    np.testing.assert_array_equal(second.toarray(), f(second_x, p).full())
    np.testing.assert_array_equal(first.toarray(), kept)  # an earlier result is not overwritten
    np.testing.assert_array_equal(dm_to_csc(f(second_x, p)).toarray(), second.toarray())


def test_sparse_output_without_parameters():
    f = _jacobian_function(0)
    x = np.linspace(-1.0, 1.0, 6)
    np.testing.assert_array_equal(SparseOutput(f)(x, np.zeros(0)).toarray(), f(x, np.zeros(0)).full())

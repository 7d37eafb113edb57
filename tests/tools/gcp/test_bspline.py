"""B-spline matrices and the cutoff-to-node-count rule (tools.md §0.3)."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.tools.gcp.bspline import bspline_matrices, derivative_matrix, fit_nodes, nodes_for_cutoff


def test_partition_of_unity_and_shape():
    n, n_p, n_pp = bspline_matrices(4, 12, 50, 0.01)
    assert n.shape == n_p.shape == n_pp.shape == (50, 12)
    np.testing.assert_allclose(n.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(n_p.sum(axis=1), 0.0, atol=1e-9)
    assert (n >= -1e-15).all()
    assert np.count_nonzero(n[25]) <= 5  # degree 4: at most 5 basis functions per sample


def test_cubic_is_reproduced_and_differentiated():
    t = np.arange(60) * 0.01
    y = 2 * t**3 - t**2 + 0.5 * t + 1
    n, n_p, _ = bspline_matrices(4, 15, t.size, 0.01)
    nodes = fit_nodes(n, y)
    np.testing.assert_allclose(n @ nodes, y, atol=1e-10)
    # central differences of the basis: exact for the derivative up to O(dt^2) inside
    inner = slice(1, -1)
    np.testing.assert_allclose((n_p @ nodes)[inner], (6 * t**2 - 2 * t + 0.5)[inner], atol=2e-4)
    d = derivative_matrix(t, 4, 15)
    np.testing.assert_allclose(d @ y, n_p @ nodes, atol=1e-9)


def test_nodes_for_cutoff_grows_with_cutoff():
    t = np.arange(101) * 0.011
    y = np.column_stack([np.sin(2 * np.pi * 1.5 * t) + 0.3 * np.sin(2 * np.pi * 7 * t), t**2])
    low, high = nodes_for_cutoff(t, y, 3.0), nodes_for_cutoff(t, y, 10.0)
    assert 11 <= low < high


def test_too_few_nodes_is_an_input_error():
    with pytest.raises(InputError, match="at least 5 nodes"):
        bspline_matrices(4, 3, 20, 0.01)

"""Mesh of intervals x points in normalized time."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.core.transcription.mesh import Mesh


def test_tutorial_mesh_times_match_the_original_output_times() -> None:
    # TorqueTOResultsV1 rows: 25 intervals x 4 LGR points + end, t_f = 0.31 s
    mesh = Mesh.uniform(25, 4)
    t = mesh.node_times * 0.31
    assert mesh.n_nodes == 101
    assert t[:5] == pytest.approx([0, 0.002633022674165486, 0.007322610880934888, 0.01130150930204246, 0.0124])


@pytest.mark.parametrize("intervals,points", [(1, 50), (25, 4), (5, 10), (3, 1)])
def test_quadrature_and_interpolation(intervals: int, points: int) -> None:
    mesh = Mesh.uniform(intervals, points)
    w = mesh.quadrature_weights
    s = mesh.times("collocation")
    assert w.sum() == pytest.approx(1.0)
    degree = 2 * points - 2
    assert w @ s**degree == pytest.approx(1 / (degree + 1), rel=1e-10)
    query = np.linspace(0, 1, 17)
    nodes = mesh.node_times
    assert np.allclose(mesh.state_interpolation(query) @ nodes**points, query**points, atol=1e-10)
    if points > 1:
        assert np.allclose(mesh.control_interpolation(query) @ s ** (points - 1), query ** (points - 1), atol=1e-9)
    assert mesh.final_extrapolation() @ s ** (points - 1) == pytest.approx(1.0)


def test_grids() -> None:
    mesh = Mesh.uniform(2, 3)
    assert list(mesh.rows("collocation")) == list(range(6))
    assert list(mesh.rows("final")) == [6] and list(mesh.rows("initial")) == [0]
    with pytest.raises(ValueError, match="unknown grid"):
        mesh.rows("everywhere")
    with pytest.raises(ValueError):
        Mesh((0.5, 0.4), (3, 3))

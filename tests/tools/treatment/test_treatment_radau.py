"""LGR nodes, weights and differentiation matrices (nmsm.core.transcription.radau)."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.transcription.radau import differentiation_matrix, lagrange_basis_at, radau_rule


@pytest.mark.parametrize("n", [1, 2, 3, 4, 7, 10, 25, 50, 80])
def test_quadrature_is_exact_to_degree_2n_minus_2(n: int) -> None:
    rule = radau_rule(n)
    tau = rule.collocation
    for k in range(2 * n - 1):
        exact = (1 - (-1) ** (k + 1)) / (k + 1)
        assert rule.weights @ tau**k == pytest.approx(exact, abs=1e-12)


@pytest.mark.parametrize("n", [1, 2, 4, 9, 50])
def test_derivative_matrix_differentiates_degree_n_polynomials(n: int) -> None:
    rule = radau_rule(n)
    x, tau = rule.nodes, rule.collocation
    for k in range(n + 1):
        derivative = k * tau ** (k - 1) if k else 0 * tau
        assert np.max(np.abs(rule.derivative @ x**k - derivative)) < 1e-9 * max(1, k**2)


@pytest.mark.parametrize("n", [2, 3, 5, 9])
def test_nodes_match_casadi_radau_points_mirrored(n: int) -> None:
    # CasADi's Radau points on [0, 1] include the right end; LGR (GPOPS) includes the left one
    right = np.array(cs.collocation_points(n, "radau"))
    ours = 0.5 * (radau_rule(n).collocation + 1)
    assert np.allclose(np.sort(1 - right), ours, atol=1e-12)


def test_fifty_points_endpoint_and_extrapolation() -> None:
    rule = radau_rule(50)
    assert rule.nodes[0] == -1 and rule.nodes[-1] == 1 and np.all(np.diff(rule.nodes) > 0)
    # extrapolating a degree-49 polynomial through the collocation points to tau = 1
    tau = rule.collocation
    assert rule.extrapolate @ tau**49 == pytest.approx(1.0, abs=1e-9)


def test_lagrange_basis_interpolates() -> None:
    x = np.linspace(-1, 1, 6)
    points = np.array([-0.3, 0.77, x[2]])
    values = lagrange_basis_at(x, points) @ (x**3 - 2 * x)
    assert np.allclose(values, points**3 - 2 * points)
    assert np.allclose(differentiation_matrix(x) @ x**5, 5 * x**4)


def test_invalid_point_count() -> None:
    with pytest.raises(ValueError, match="at least 1"):
        radau_rule(0)

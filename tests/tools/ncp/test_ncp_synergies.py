"""Synergy parameterization: spline nodes, block-diagonal vectors, sharing, normalization."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from nmsm.tools.ncp.solution import SynergySolution
from nmsm.tools.ncp.spline import commands_from_nodes, interpolation_matrix, nodes_from_commands
from nmsm.tools.ncp.symmetry import mirror_muscle_map, mirror_name
from nmsm.tools.ncp.synergies import SynergyGroup, SynergyLayout, activations, normalize_by_max_weight


def test_interpolation_matrix_is_not_a_knot_cubic_spline() -> None:
    rng = np.random.default_rng(3)
    nodes = rng.uniform(0, 1, (21, 4))
    expected = CubicSpline(np.linspace(0, 100, 21), nodes, bc_type="not-a-knot")(np.linspace(0, 100, 101))
    assert np.allclose(interpolation_matrix(21, 101) @ nodes, expected, atol=1e-13)
    assert np.allclose(interpolation_matrix(21, 101).sum(axis=1), 1.0)  # constants are reproduced


def test_nodes_from_commands_round_trip() -> None:
    nodes = np.abs(np.sin(np.linspace(0, 3, 21)))[:, None] * np.array([[1.0, 0.5]])
    assert np.allclose(nodes_from_commands(commands_from_nodes(nodes, 101), 21), nodes, atol=1e-12)


def _layout(shared: bool = False) -> SynergyLayout:
    right = SynergyGroup("RightLeg", ["a_r", "b_r", "c_r"], 2)
    left = SynergyGroup("LeftLeg", ["b_l", "a_l", "c_l"], 2)
    share = (None, (0, mirror_muscle_map(right.muscles, left.muscles))) if shared else None
    return SynergyLayout([right, left], n_nodes=21, shared_from=share)


def test_weight_matrix_is_block_diagonal() -> None:
    layout = _layout()
    w1 = np.arange(6.0).reshape(2, 3) + 1
    w2 = -np.arange(6.0).reshape(2, 3) - 1
    w = layout.weight_matrix([w1, w2])
    assert w.shape == (4, 6)
    assert np.array_equal(w[:2, :3], w1) and np.array_equal(w[2:, 3:], w2)
    assert not w[:2, 3:].any() and not w[2:, :3].any()
    assert layout.synergy_names == ("RightLeg_1", "RightLeg_2", "LeftLeg_1", "LeftLeg_2")
    assert layout.groups[0].weight_sum == pytest.approx(0.03)


def test_shared_group_mirrors_muscles_by_name() -> None:
    layout = _layout(shared=True)
    assert layout.free_groups == (0,)
    w1 = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    w = layout.weight_matrix([w1])
    # left group lists b_l, a_l, c_l: columns are right's b, a, c
    assert np.array_equal(w[2:, 3:], w1[:, [1, 0, 2]])
    symbolic = cs.MX.sym("w", 2, 3)
    numeric = cs.Function("f", [symbolic], [layout.weight_matrix([symbolic])])(w1)
    assert np.array_equal(np.asarray(numeric), w)


def test_normalization_keeps_activations_and_sets_max_to_one() -> None:
    rng = np.random.default_rng(0)
    weights = rng.uniform(0, 0.02, (3, 5))
    weights[2] = 0.0
    commands = [rng.uniform(0, 5, (11, 3)), rng.uniform(0, 5, (7, 3))]
    new_weights, new_commands, factors = normalize_by_max_weight(weights, commands)
    assert np.allclose(new_weights[:2].max(axis=1), 1.0)
    assert not new_weights[2].any() and factors[2] == 1.0
    for before, after in zip(commands, new_commands):
        assert np.allclose(activations(weights, before), activations(new_weights, after))


def test_solution_normalized_and_group_weights() -> None:
    layout = _layout()
    weights = layout.weight_matrix([np.full((2, 3), 0.01), np.full((2, 3), 0.02)])
    solution = SynergySolution(layout, weights, [np.ones((5, 4))], ["t"], nodes=[np.ones((21, 4))])
    normalized = solution.normalized()
    assert np.allclose(normalized.group_weights(1), 1.0)
    assert np.allclose(normalized.activations(0), solution.activations(0))
    assert np.allclose(normalized.nodes[0][:, 2:], 0.02)


def test_invalid_groups() -> None:
    with pytest.raises(ValueError, match="asks for 4 synergies but has only 3"):
        SynergyGroup("g", ["a", "b", "c"], 4)
    with pytest.raises(ValueError, match="more than one synergy group"):
        SynergyLayout([SynergyGroup("g", ["a", "b"], 1), SynergyGroup("h", ["b", "c"], 1)])


def test_mirror_names_and_position_fallback() -> None:
    assert mirror_name("soleus_r") == "soleus_l" and mirror_name("IO2_l") == "IO2_r" and mirror_name("x") is None
    assert mirror_muscle_map(["a_r", "b_r"], ["b_l", "a_l"]) == (1, 0)
    with pytest.warns(UserWarning, match="pairing .* by position"):
        assert mirror_muscle_map(["a_r", "b_r"], ["x", "y"]) == (0, 1)
    with pytest.raises(ValueError, match="equal size"):
        mirror_muscle_map(["a_r"], ["a_l", "b_l"])

"""Synergy Extrapolation: commands (PCA as the original, NMF), categories, weights layout."""

from __future__ import annotations

import functools

import casadi as cs
import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.tools.mtp import synx


def test_pca_commands_reproduce_the_original(shared_data):
    folder = shared_data / "mtp" / "cost_function_unit_2023" / "with_synergy_extrapolation" / "npz"
    d = np.load(folder / "initialValues.npz")
    emg = [d["inputData.emgData"][t].T for t in range(4)]
    normalized = synx.normalize_emg(emg)
    for i, category in enumerate(synx.categorize_trials("trial", [f"t{k}" for k in range(4)])):
        ours = synx.synergy_commands(normalized, [category], 5, "PCA")[0]
        assert np.abs(ours - d[f"inputData.extrapolationCommands{{{i}}}"]).max() <= 1e-12
    for i, category in enumerate([[0, 1], [2, 3]]):
        ours = synx.synergy_commands(normalized, [category], 5, "PCA")[0]
        assert np.abs(ours - d[f"inputData.residualCommands{{{i}}}"]).max() <= 1e-12


def test_categories():
    names = ["speed1_gait_1", "speed1_gait_2", "speed2_squat_1"]
    assert synx.categorize_trials("trial", names) == [[0], [1], [2]]
    assert synx.categorize_trials("subject", names) == [[0, 1, 2]]
    assert synx.categorize_trials("task", names, ["speed1", "speed2"]) == [[0, 1], [2]]
    assert synx.categorize_trials("task", names) == [[0, 1, 2]]
    with pytest.raises(InputError, match="none of the task names"):
        synx.categorize_trials("task", names, ["speed1"])
    with pytest.raises(InputError, match="trial, task or subject"):
        synx.categorize_trials("session", names)


def test_nmf_reconstructs_low_rank_data():
    rng = np.random.default_rng(4)
    c_true = rng.random((120, 3))
    w_true = rng.random((3, 8))
    c, w = synx.nmf(c_true @ w_true, 3, replicates=5)
    assert np.all(c >= 0) and np.all(w >= 0)
    assert np.linalg.norm(c @ w - c_true @ w_true) <= 1e-3 * np.linalg.norm(c_true @ w_true)


@functools.lru_cache(maxsize=None)
def _setup(method="PCA", residual="trial"):
    rng = np.random.default_rng(5)
    emg = [rng.random((21, 3)) for _ in range(2)]
    return emg, synx.build_synergy_extrapolation(
        emg, ["a", "b"], method=method, n_synergies=2, extrapolation_categorization="subject",
        residual_categorization=residual, missing_muscles=[(3,), (4,)], channel_muscles=[(0,), (1,), (2,)])


def test_weight_layout_and_excitations():
    emg, s = _setup()
    assert s.n_extrapolation_weights == 3 * 1 * 2  # (K + 1) x categories x missing channels
    assert s.n_residual_weights == 3 * 2 * 3  # (K + 1) x categories x measured channels
    w = np.zeros(s.n_weights)
    w[2] = 0.25  # bias of missing channel 0 (first category)
    w[s.n_extrapolation_weights + 3 + 2] = -0.1  # bias of measured channel 1, residual category 0 (trial a)
    expanded = [np.column_stack([x, np.zeros((21, 2))]) for x in emg]
    scale = np.array([0.5, 0.5, 0.5, 0.8, 0.8])
    samples = [np.array(cs.Function("f", [], [x]).call([])[0].full()) for x in s.excitation_samples(expanded, scale, cs.DM(w))]
    assert np.allclose(samples[0][:, 3], 0.8 * 0.25)  # s_emg * u for the extrapolated muscle
    assert np.allclose(samples[0][:, 1], 0.5 * emg[0][:, 1] - 0.1)  # s_emg * EMG + residual
    assert np.allclose(samples[1][:, 1], 0.5 * emg[1][:, 1])  # other trial: its own residual (0)
    bounds = np.array(cs.Function("g", [], [s.extrapolated_bounds_expression(cs.DM(w))]).call([])[0].full()).ravel()
    assert bounds.size == 2 * 21 * 2 and np.allclose(bounds[:21], 0.25)


def test_nmf_setup_has_no_bias():
    _, s = _setup("NMF")
    assert s.per_vector == 2
    assert all(np.all(c >= 0) for c in s.extrapolation_commands)


def test_zero_channel_is_an_error():
    emg = [np.zeros((11, 2)), np.zeros((11, 2))]
    emg[0][:, 0] = 1.0
    with pytest.raises(InputError, match="zero in every trial"):
        synx.normalize_emg(emg)


def test_nmf_extrapolation_weights_are_non_negative():
    """NMF: extrapolated excitations are non-negative combinations of non-negative commands."""
    _, s = _setup("NMF")
    low, high = s.weight_bounds(-100.0, 100.0)
    assert low.shape == high.shape == (s.n_weights,)
    assert np.all(low[: s.n_extrapolation_weights] == 0.0)
    assert np.all(low[s.n_extrapolation_weights :] == -100.0)  # residuals stay signed
    _, p = _setup("PCA")
    assert np.all(p.weight_bounds()[0] == -100.0)


@pytest.mark.parametrize("method", ["PCA", "NMF"])
def test_extrapolated_excitation_constraint_in_problem(method):
    """Both methods bound the extrapolated excitations to [0, 1] inside the MTP problem."""
    from nmsm.examples.synthetic_mtp import make_synthetic_mtp
    from nmsm.tools.mtp.evaluation import initial_fiber_lengths
    from nmsm.tools.mtp.problem import MtpState, TaskSettings, build_task_problem
    import attrs

    case = make_synthetic_mtp(n_muscles=3, n_trials=2, seed=3)
    data = case.data
    emg = [t.emg[:, :2] for t in data.trials]  # muscle 2 has no EMG
    sx = synx.build_synergy_extrapolation(
        emg, [t.name for t in data.trials], method=method, n_synergies=1, extrapolation_categorization="subject",
        residual_categorization="trial", missing_muscles=[(2,)], channel_muscles=[(0,), (1,)])
    data = attrs.evolve(data, channel_of_muscle=np.array([0, 1, -1]), synx=sx,
                        trials=tuple(attrs.evolve(t, emg=t.emg[:, :2]) for t in data.trials))
    problem, _ = build_task_problem(data, MtpState.initial(data), TaskSettings(), initial_fiber_lengths(data),
                                    lift=False)
    names = [c.name for c in problem.constraints]
    assert "extrapolated_excitation_0_1" in names
    block = problem.variables["synergy_weights"]
    lower = np.asarray(block.lower).ravel()
    assert lower[: sx.n_extrapolation_weights].min() == (0.0 if method == "NMF" else -100.0)

"""Polynomial surrogate muscle geometry: basis, fit, CasADi evaluation, file format, sampling."""

from __future__ import annotations

import json
from math import comb

import casadi as cs
import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.model.polynomial import MonomialBasis, monomial_exponents
from nmsm.model.surrogate import (
    GeometrySamples,
    SurrogateModel,
    fit_muscle_surrogate,
    fit_surrogate_model,
    spanned_coordinates,
)
from nmsm.model.surrogate_sampling import coordinate_padding, latin_hypercube_poses


# ---- a synthetic "muscle": a known smooth length function of three coordinates ----------------
def _length(q: np.ndarray) -> np.ndarray:
    """Exactly a degree-3 polynomial in (q0, q1); q2 does not act on this muscle."""
    a, b = q[:, 0], q[:, 1]
    return 0.3 + 0.02 * a - 0.015 * b + 0.004 * a * b + 0.003 * a**3 - 0.001 * b**2 * a


def _gradient(q: np.ndarray) -> np.ndarray:
    a, b = q[:, 0], q[:, 1]
    da = 0.02 + 0.004 * b + 0.009 * a**2 - 0.001 * b**2
    db = -0.015 + 0.004 * a - 0.002 * b * a
    return np.column_stack([da, db, np.zeros_like(a)])


def _samples(n: int, seed: int) -> GeometrySamples:
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1.2, 1.4, size=(n, 3))
    lengths = np.column_stack([_length(q), 0.1 + 0.05 * q[:, 2]])  # second muscle spans only q2
    arms = np.zeros((n, 2, 3))
    arms[:, 0, :] = -_gradient(q)
    arms[:, 1, 2] = -0.05
    return GeometrySamples(("c0", "c1", "c2"), ("m_ab", "m_c"), q, lengths, arms)


# ---- basis -------------------------------------------------------------------------------------
@pytest.mark.parametrize("k,p", [(1, 5), (3, 4), (6, 5), (4, 0)])
def test_monomial_count_and_degrees(k: int, p: int) -> None:
    e = monomial_exponents(k, p)
    assert e.shape == (comb(k + p, p), k)
    assert len({tuple(r) for r in e.tolist()}) == e.shape[0]
    assert e.sum(axis=1).max() == p and np.all(e >= 0)
    assert np.all(np.diff(e.sum(axis=1)) >= 0)  # graded order


def test_basis_values_and_gradients_match_direct_formula() -> None:
    e = monomial_exponents(3, 4)
    basis = MonomialBasis.from_exponents(e)
    x = np.random.default_rng(1).uniform(-1, 1, (7, 3))
    phi = basis.matrix(x)
    np.testing.assert_allclose(phi, np.prod(x[:, None, :] ** e[None, :, :], axis=2), rtol=1e-13, atol=1e-15)
    grads = basis.gradient_matrices(phi)
    h = 1e-6
    for j in range(3):
        dx = np.zeros(3)
        dx[j] = h
        fd = (basis.matrix(x + dx) - basis.matrix(x - dx)) / (2 * h)
        np.testing.assert_allclose(grads[j], fd, atol=1e-8)


def test_derivative_coefficients_differentiate_the_polynomial() -> None:
    basis = MonomialBasis.from_exponents(monomial_exponents(2, 3))
    c = np.arange(1.0, basis.n_terms + 1)
    x = np.array([[0.3, -0.7]])
    grads = basis.gradient_matrices(basis.matrix(x))
    for j in range(2):
        assert (basis.matrix(x) @ basis.derivative_coefficients(c, j))[0] == pytest.approx((grads[j] @ c)[0])


def test_basis_rejects_exponent_sets_missing_parents() -> None:
    with pytest.raises(ValueError, match="lacks"):
        MonomialBasis.from_exponents(np.array([[0, 0], [2, 0]]))


# ---- fitting -------------------------------------------------------------------------------------
def test_fit_recovers_a_polynomial_exactly() -> None:
    s = _samples(200, 0)
    m = fit_muscle_surrogate("m_ab", ("c0", "c1"), s.q[:, :2], s.lengths[:, 0], s.moment_arms[:, 0, :2], degree=3)
    test = _samples(50, 9)
    np.testing.assert_allclose(m.lengths(test.q[:, :2]), _length(test.q), atol=1e-12)
    np.testing.assert_allclose(m.moment_arms(test.q[:, :2]), -_gradient(test.q)[:, :2], atol=1e-12)


def test_spanned_coordinates_use_epsilon() -> None:
    arms = np.array([[1e-3, 5e-5, 0.0], [-2e-3, -1e-4, 0.0]])
    assert spanned_coordinates(arms, ("a", "b", "c"), 1e-4) == ("a",)
    assert spanned_coordinates(arms, ("a", "b", "c"), 1e-5) == ("a", "b")


def test_fit_surrogate_model_selects_coordinates_and_reports_held_out_accuracy() -> None:
    s = _samples(300, 0)
    model = fit_surrogate_model(s, degree=3, epsilon=1e-4, holdout_fraction=0.25, seed=3)
    assert model.muscle_names == ("m_ab", "m_c")
    assert model["m_ab"].coordinates == ("c0", "c1")
    assert model["m_c"].coordinates == ("c2",)
    acc = model["m_ab"].accuracy
    assert acc is not None and acc.n_poses == 75 and model.metadata["n_fitting_poses"] == 225
    assert acc.length_rms < 1e-12 and acc.worst_moment_arm_rms < 1e-12
    # a model too simple for the data shows its error on held-out poses
    coarse = fit_surrogate_model(s, degree=1, epsilon=1e-4, holdout_fraction=0.25, seed=3)
    assert coarse["m_ab"].accuracy.length_rms > 1e-4


def test_held_out_accuracy_is_measured_on_poses_not_used_for_fitting() -> None:
    s = _samples(120, 0)
    noisy = GeometrySamples(s.coordinates, s.muscles, s.q,
                            s.lengths + np.random.default_rng(5).normal(0, 1e-3, s.lengths.shape), s.moment_arms)
    model = fit_surrogate_model(noisy, degree=5, epsilon=1e-4, holdout_fraction=0.3, seed=1)
    fit_part, held_out = noisy.split(0.3, seed=1)
    assert held_out.n_poses == 36
    on_fit = model.accuracy(fit_part)["m_ab"].length_rms
    on_held = model["m_ab"].accuracy.length_rms
    assert on_held == pytest.approx(model.accuracy(held_out)["m_ab"].length_rms)
    assert on_held > on_fit  # overfitting shows only on the held-out poses


def test_muscle_without_spanned_coordinate_is_excluded() -> None:
    s = _samples(60, 0)
    arms = s.moment_arms.copy()
    arms[:, 1, :] = 0.0
    model = fit_surrogate_model(GeometrySamples(s.coordinates, s.muscles, s.q, s.lengths, arms), degree=2,
                                holdout_fraction=0.0)
    assert model.excluded_muscles == ("m_c",) and model.muscle_names == ("m_ab",)
    assert model["m_ab"].accuracy is None


def test_too_few_poses_is_an_input_error() -> None:
    s = _samples(5, 0)  # 5 poses x 3 equations < 21 terms of degree 5 in two coordinates
    with pytest.raises(InputError, match="sample poses"):
        fit_surrogate_model(s, degree=5, holdout_fraction=0.0)


# ---- evaluation ----------------------------------------------------------------------------------
def test_casadi_function_matches_numpy_and_velocity_is_chain_rule() -> None:
    s = _samples(200, 0)
    model = fit_surrogate_model(s, degree=3, holdout_fraction=0.0)
    rng = np.random.default_rng(4)
    q = rng.uniform(-1, 1, (5, 3))
    qdot = rng.normal(size=(5, 3))
    numeric = model.evaluate(q, qdot)
    f = model.function()
    for i in range(5):
        lengths, velocities, arms = (np.asarray(v) for v in f(q[i], qdot[i]))
        np.testing.assert_allclose(lengths.ravel(), numeric.lengths[i], atol=1e-14)
        np.testing.assert_allclose(arms, numeric.moment_arms[i], atol=1e-14)
        np.testing.assert_allclose(velocities.ravel(), -(arms @ qdot[i]), atol=1e-14)
    # exact derivative: CasADi's jacobian of the length equals -moment arms
    qs = cs.SX.sym("q", 3)
    jac = cs.Function("j", [qs], [cs.jacobian(f(qs, cs.DM.zeros(3))[0], qs)])
    np.testing.assert_allclose(np.asarray(jac(q[0])), -numeric.moment_arms[0], atol=1e-13)
    # velocities of a time path equal d/dt of lengths
    t, h = 0.4, 1e-6
    path = lambda tt: np.array([np.sin(tt), 0.5 * tt**2, np.cos(2 * tt)])  # noqa: E731
    speed = np.array([np.cos(t), t, -2 * np.sin(2 * t)])
    v = np.asarray(f(path(t), speed)[1]).ravel()
    fd = (np.asarray(f(path(t + h), speed)[0]) - np.asarray(f(path(t - h), speed)[0])).ravel() / (2 * h)
    np.testing.assert_allclose(v, fd, atol=1e-9)


def test_function_accepts_a_longer_coordinate_list_and_checks_coverage() -> None:
    model = fit_surrogate_model(_samples(200, 0), degree=3, holdout_fraction=0.0)
    f = model.function(coordinates=("pelvis_tx", "c2", "c1", "c0"))
    q = np.array([9.0, 0.3, -0.2, 0.5])
    lengths, _, arms = (np.asarray(v) for v in f(q, np.zeros(4)))
    ref = model.evaluate(q[[3, 2, 1]][None, :])
    np.testing.assert_allclose(lengths.ravel(), ref.lengths[0], atol=1e-14)
    np.testing.assert_allclose(arms[:, [3, 2, 1]], ref.moment_arms[0], atol=1e-14)
    assert np.all(arms[:, 0] == 0)
    with pytest.raises(InputError, match="needs coordinates c0"):
        model.function(coordinates=("c1", "c2"))
    mapped = model.function().map(4)
    assert mapped.size_out(2) == (2, 12)


# ---- file format -----------------------------------------------------------------------------------
def test_save_load_round_trip_is_exact(tmp_path) -> None:
    model = fit_surrogate_model(_samples(200, 0), degree=4, holdout_fraction=0.2)
    path = model.save(tmp_path / "sub" / "surrogate.json")
    loaded = SurrogateModel.load(path)
    assert loaded.coordinates == model.coordinates and loaded.muscle_names == model.muscle_names
    for a, b in zip(model.muscles, loaded.muscles):
        assert np.array_equal(a.coefficients, b.coefficients) and np.array_equal(a.exponents, b.exponents)
        assert np.array_equal(a.center, b.center) and np.array_equal(a.scale, b.scale)
        assert a.accuracy == b.accuracy
    doc = json.loads(path.read_text())
    assert doc["format"] == "nmsm-surrogate-model" and doc["degree"] == 4


def test_load_errors_name_the_file(tmp_path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError, match="bad.json"):
        SurrogateModel.load(bad)
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"format": "something"}))
    with pytest.raises(InputError, match="refit from the sample data"):
        SurrogateModel.load(other)
    broken = tmp_path / "broken.json"
    broken.write_text(json.dumps({"format": "nmsm-surrogate-model", "version": 1, "coordinates": []}))
    with pytest.raises(InputError, match="malformed"):
        SurrogateModel.load(broken)


# ---- sampling --------------------------------------------------------------------------------------
def test_latin_hypercube_poses_stay_in_padded_clipped_box_and_stratify() -> None:
    ref = np.array([[0.0, 1.0, 5.0], [0.5, 0.0, 5.0]])
    lower, upper = coordinate_padding(("a", "b", "t"), (True, True, False), 0.2, 0.01, {"b": (-0.1, 0.3)})
    np.testing.assert_allclose(lower, [-0.2, -0.1, -0.01])
    np.testing.assert_allclose(upper, [0.2, 0.3, 0.01])
    poses = latin_hypercube_poses(ref, lower, upper, [-np.inf, -np.inf, -np.inf], [0.6, 1.1, np.inf], 40, seed=2)
    assert poses.shape == (80, 3)
    first, second = poses[:40], poses[40:]
    assert first[:, 0].min() >= -0.2 and first[:, 0].max() <= 0.2
    assert first[:, 1].min() >= 0.9 and first[:, 1].max() <= 1.1  # clipped at the range max 1.1
    assert second[:, 0].max() <= 0.6  # clipped
    # one sample per stratum in every dimension
    u = (first[:, 0] + 0.2) / 0.4
    assert sorted(np.floor(u * 40).astype(int).tolist()) == list(range(40))
    again = latin_hypercube_poses(ref, lower, upper, None, None, 40, seed=2)
    assert np.array_equal(latin_hypercube_poses(ref, lower, upper, None, None, 40, seed=2), again)


def test_padding_for_unknown_coordinate_is_an_error() -> None:
    with pytest.raises(InputError, match="zzz"):
        coordinate_padding(("a",), (True,), 0.1, 0.0, {"zzz": (0, 1)})

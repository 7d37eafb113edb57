"""Hill-type muscle model (:mod:`nmsm.model.hill`): curves, stability, CasADi = numpy, activation."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.model import hill


def _cs(f, *args):
    syms = [cs.SX.sym(f"x{i}") for i in range(len(args))]
    fun = cs.Function("f", syms, [f(*syms)])
    return np.array([float(fun(*vals)) for vals in zip(*[np.atleast_1d(a) for a in args])])


def test_curve_values_at_reference_points():
    # optimal length gives ~1 active force, 0 velocity gives exactly 1
    assert hill.active_force_length(1.0) == pytest.approx(1.0, abs=1e-3)
    assert hill.force_velocity(0.0) == pytest.approx(1.0, abs=1e-12)
    assert hill.force_velocity(-1.0) == pytest.approx(0.0, abs=5e-3)  # maximum shortening velocity
    assert hill.force_velocity(1.0) > 1.3  # eccentric enhancement
    e1, e2, e3 = hill.PASSIVE_FORCE_LENGTH_E
    assert hill.passive_force_length(e3) == pytest.approx(e1 * np.log(2.0), rel=1e-14)


def test_passive_softplus_is_stable():
    l = np.array([-50.0, 0.0, 1.0, 2.0, 60.0, 1e3])
    values = hill.passive_force_length(l)
    assert np.all(np.isfinite(values))
    e1, e2, e3 = hill.PASSIVE_FORCE_LENGTH_E
    assert values[-1] == pytest.approx(e1 * e2 * (1e3 - e3), rel=1e-12)  # linear asymptote, no overflow
    assert np.all(np.isfinite(_cs(hill.passive_force_length, l)))
    # CasADi gradient finite too
    x = cs.SX.sym("x")
    grad = cs.Function("g", [x], [cs.gradient(hill.passive_force_length(x), x)])
    assert float(grad(1e3)) == pytest.approx(e1 * e2, rel=1e-12)


@pytest.mark.parametrize("curves", [hill.CURVES, hill.CURVES_2023], ids=["current", "2023"])
@pytest.mark.parametrize("func", [hill.active_force_length, hill.force_velocity, hill.passive_force_length])
def test_casadi_matches_numpy(func, curves):
    x = np.linspace(-0.9, 1.8, 37)
    assert np.allclose(_cs(lambda v: func(v, curves), x), func(x, curves), rtol=1e-14, atol=1e-14)


def test_2023_curves_are_the_earlier_fits():
    """The 2023 f_L is De Groote et al. 2016's (peak 0.9994 at l = 1), its f_V was not
    normalized (f_V(0) = 1.0005); f_P is unchanged; the forces take the set given."""
    assert hill.active_force_length(1.0, hill.CURVES_2023) == pytest.approx(0.99943, abs=1e-5)
    assert hill.force_velocity(0.0, hill.CURVES_2023) == pytest.approx(1.000513, abs=1e-6)
    assert hill.CURVES_2023.passive_force_length == hill.CURVES.passive_force_length
    a, l, v, f0, alpha = 0.4, 0.9, 0.2, 1000.0, 0.1
    expected = f0 * (a * hill.active_force_length(l, hill.CURVES_2023) * hill.force_velocity(v, hill.CURVES_2023)
                     + hill.passive_force_length(l)) * np.cos(alpha)
    assert hill.tendon_force(a, l, v, f0, alpha, hill.CURVES_2023) == pytest.approx(expected, rel=1e-14)
    assert hill.tendon_force(a, l, v, f0, alpha) != pytest.approx(expected, rel=1e-4)


def test_forces_and_moments():
    a, l, v = 0.3, 1.05, -0.1
    f0, alpha = 2000.0, 0.2
    total = hill.tendon_force(a, l, v, f0, alpha)
    assert total == pytest.approx(hill.active_tendon_force(a, l, v, f0, alpha) + hill.passive_tendon_force(l, f0, alpha))
    assert total == pytest.approx(
        f0 * (a * hill.active_force_length(l) * hill.force_velocity(v) + hill.passive_force_length(l)) * np.cos(alpha))
    arms = np.array([[[0.05, -0.02], [0.0, 0.03]]])  # (frames=1, coords=2, muscles=2)
    forces = np.array([[100.0, 200.0]])
    assert np.allclose(hill.joint_moments(arms, forces), [[0.05 * 100 - 0.02 * 200, 0.03 * 200]])


def test_fiber_kinematics():
    assert hill.normalized_fiber_length(0.35, 0.1, 0.25, 0.0) == pytest.approx(1.0)
    assert hill.normalized_fiber_length(0.35, 0.1, 0.25, np.pi / 3) == pytest.approx(2.0)
    assert hill.normalized_fiber_velocity(-1.0, 0.1, 0.0, 10.0) == pytest.approx(-1.0)


def test_volume_roundtrip():
    v = hill.muscle_volume(1500.0, 0.12, 610e3)
    assert hill.max_isometric_force_from_volume(v, 0.12, 610e3) == pytest.approx(1500.0)
    assert hill.max_isometric_force_from_volume(v, 0.24, 610e3) == pytest.approx(750.0)


def test_neural_activation_step_response():
    dt, tau = 0.001, 0.015
    e = np.zeros(400)
    e[50:] = 1.0
    n = hill.neural_activation(e, tau, dt)
    assert n[:50].max() == 0.0
    # activation towards 1 with time constant tau (dn/dt = (e/tau)(1 - n) for e = 1)
    k = 50 + int(round(tau / dt))
    assert n[k] == pytest.approx(1 - np.exp(-1), abs=0.02)
    assert n[-1] == pytest.approx(1.0, abs=1e-6)
    # deactivation is 4x slower
    e2 = np.ones(800)
    e2[200:] = 0.0
    m = hill.neural_activation(e2, tau, dt)
    j = 200 + int(round(4 * tau / dt))
    assert m[j] / m[199] == pytest.approx(np.exp(-1), abs=0.02)


def test_neural_activation_casadi_matches_numpy():
    rng = np.random.default_rng(0)
    e = rng.random(60)
    f = hill.neural_activation_function(60)
    assert np.allclose(np.array(f(e, 0.02, 0.01)).ravel(), hill.neural_activation(e, 0.02, 0.01), atol=1e-15)
    # vectorized numpy over muscles x frames
    es = rng.random((3, 60))
    taus = np.array([0.01, 0.02, 0.03])
    assert np.allclose(hill.neural_activation(es, taus, 0.01)[1], hill.neural_activation(es[1], 0.02, 0.01))


def test_activation_nonlinearity():
    n = np.linspace(0, 1, 11)
    assert np.allclose(hill.activation_nonlinearity(n, 0.0), n)
    a = hill.activation_nonlinearity(n, 0.3)
    assert a[-1] == pytest.approx(1.0, abs=1e-3)
    assert np.all(np.diff(a) > 0)
    assert np.allclose(_cs(lambda x: hill.activation_nonlinearity(x, 0.3), n), a, atol=1e-15)


def test_clip_negative():
    x = np.array([-1.0, 0.0, 2.0])
    assert np.array_equal(hill.clip_negative(x), [0.0, 0.0, 2.0])
    s = 0.01
    x = np.linspace(-3 * s, 3 * s, 601)
    hard = np.maximum(x, 0.0)
    smooth = hill.clip_negative(x, s)
    assert np.all(smooth >= hard)
    assert np.max(smooth - hard) == pytest.approx(3 * s / 16, rel=1e-12)  # at 0
    outside = np.abs(x) >= s
    assert np.array_equal(smooth[outside], hard[outside])
    assert np.allclose(_cs(lambda v: hill.clip_negative(v, s), x), smooth, atol=1e-15)


def test_clip_negative_ramp_is_twice_differentiable():
    """Value, slope and curvature of the smooth ramp are continuous at +-s (exact AD)."""
    s = 0.01
    v = cs.SX.sym("v")
    f = hill.clip_negative(v, s)
    fun = cs.Function("f", [v], [f, cs.gradient(f, v), cs.hessian(f, v)[0]])
    for edge, (value, slope) in ((-s, (0.0, 0.0)), (s, (s, 1.0))):
        for side in (edge * (1 - 1e-9), edge * (1 + 1e-9)):
            out = [float(o) for o in fun(side)]
            assert out[0] == pytest.approx(value, abs=1e-10)
            assert out[1] == pytest.approx(slope, abs=1e-6)
            assert out[2] == pytest.approx(0.0, abs=1e-5)
    assert float(fun(0.0)[2]) == pytest.approx(3 / (4 * s))


def test_active_force_length_guarded_where_a_width_vanishes():
    """The second Gaussian's width ``b3 + b4 l`` is 0 at l = 0.1465 (a fiber far too short,
    e.g. tendon slack length driven up to the muscle-tendon length): value and exact
    derivatives stay finite, and nothing changes away from that point."""
    b3, b4 = hill.ACTIVE_FORCE_LENGTH_B[2][1], hill.ACTIVE_FORCE_LENGTH_B[3][1]
    singular = -b3 / b4
    x = cs.SX.sym("x")
    f = hill.active_force_length(x)
    fun = cs.Function("f", [x], [f, cs.gradient(f, x), cs.hessian(f, x)[0]])
    for value in (singular, -2.0, 0.0, 1e-3):
        assert all(np.isfinite(float(v)) for v in fun(value))
    with np.errstate(divide="raise", invalid="raise", over="raise"):
        assert np.isfinite(hill.active_force_length(np.array([singular, -5.0, 0.0])).all())
    # away from the point the floor changes nothing: compare with the unguarded formula
    l = np.linspace(0.3, 1.8, 31)
    b1, b2, b3s, b4s = hill.ACTIVE_FORCE_LENGTH_B
    plain = sum(b1[i] * np.exp(-0.5 * (l - b2[i]) ** 2 / (b3s[i] + b4s[i] * l) ** 2) for i in range(3))
    assert np.array_equal(hill.active_force_length(l), plain)

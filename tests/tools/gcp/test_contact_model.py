"""The elastic-foundation contact model (nmsm.model.foot_contact) against the spec's
formulas written out independently here, its K-linear form, and the original's outputs."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.model.foot_contact import (CONTACT_PARAMETERS, ContactParameters, contact_function, elastic_force,
                                     unit_loads)


def reference_contact(positions, velocities, k, parameters, reference):
    """tools.md §6.3, line by line, in numpy."""
    damping, mu_d, mu_v, rest, latch, belt = parameters
    k_low, h_off, c, y_max = 0.1, 1e-3, 1e-3, 1e-2
    y = 0.7 * np.tanh((positions[1] - rest) / 0.7)
    v = (k + k_low) / (k - k_low)
    s = (k - k_low) / 2
    lc = lambda x: np.log(np.cosh(x))  # noqa: E731
    f_el = -s * (v * y - c * lc((y + h_off) / c)) + s * (v * y_max - c * lc((y_max + h_off) / c))
    fy = f_el * (1 - damping * velocities[1])
    ux, uz = velocities[0] + belt, velocities[2]
    vs = np.sqrt(ux**2 + uz**2)
    vs = np.where(vs < 1e-10, 0.0, vs)
    magnitude = fy * (mu_d * np.tanh(vs / latch) + mu_v * vs)
    fx, fz = -ux * magnitude / (vs + 1e-4), -uz * magnitude / (vs + 1e-4)
    forces = np.vstack([fx, fy, fz])
    lever = np.vstack([positions[0] - reference[0], np.zeros_like(fx), positions[2] - reference[2]])
    moment = np.cross(lever.T, forces.T).sum(axis=0)
    return forces.sum(axis=1), moment, forces


@pytest.fixture
def springs():
    rng = np.random.default_rng(3)
    n = 25
    positions = np.vstack([rng.uniform(-0.05, 0.25, n), rng.uniform(-0.004, 0.03, n), rng.uniform(-0.05, 0.05, n)])
    velocities = rng.normal(0.0, 0.5, (3, n))
    k = rng.uniform(500.0, 6000.0, n)
    parameters = np.array([0.4, 0.65, 0.3, 0.006, 0.05, 1.3])
    reference = np.array([0.1, 0.2, 0.01])
    return positions, velocities, k, parameters, reference


def test_matches_spec_formulas(springs):
    force, moment, per_spring = contact_function(springs[2].size)(*springs)
    ref_force, ref_moment, ref_springs = reference_contact(*springs)
    np.testing.assert_allclose(np.array(per_spring), ref_springs, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(np.array(force).ravel(), ref_force, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(np.array(moment).ravel(), ref_moment, rtol=1e-12, atol=1e-9)


def test_linear_in_spring_constants(springs):
    positions, velocities, k, parameters, reference = springs
    a, b = unit_loads(cs.DM(positions), cs.DM(velocities), cs.DM(parameters), cs.DM(reference))
    force, moment, _ = contact_function(k.size)(*springs)
    combined = np.array(cs.mtimes(a, k) + b).ravel()
    np.testing.assert_allclose(combined, np.concatenate([np.array(force).ravel(), np.array(moment).ravel()]),
                               rtol=1e-11, atol=1e-9)


def test_elastic_force_shape():
    k = 3000.0
    heights = np.array([-0.004, -0.002, 0.0, 0.01, 0.05])
    f = np.array(elastic_force(cs.DM(heights), k, 0.0)).ravel()
    # in contact: -K (y + h_off), h_off = 1 mm (away from the transition), zero at y_max,
    # slope k_low far above
    assert f[0] == pytest.approx(-k * (-0.004 + 1e-3), rel=1e-3)
    assert 0.0 < f[2] < f[1] < f[0]  # smooth, monotonic transition
    assert f[4] == pytest.approx(-0.1 * (0.05 - 0.01), rel=5e-3)
    assert f[3] == pytest.approx(0.0, abs=1e-6)
    slope = (np.array(elastic_force(cs.DM([0.05 + 1e-4]), k, 0.0)) - np.array(elastic_force(cs.DM([0.05]), k, 0.0)))
    clamp = 1 - np.tanh(0.05 / 0.7) ** 2  # d/dh of the 0.7 tanh(h/0.7) clamp
    assert float(slope.ravel()[0]) / 1e-4 == pytest.approx(-0.1 * clamp, rel=1e-3)


def test_parameter_vector_order():
    p = ContactParameters(0.1, 0.2, 0.3, 0.4, 0.5, 0.6)
    assert tuple(p.vector()) == (0.1, 0.2, 0.3, 0.4, 0.5, 0.6)
    assert CONTACT_PARAMETERS[3] == "resting_spring_length"

"""Reference splines: numeric and symbolic evaluation, derivatives in time and in t_f."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.core.splines import ReferenceSplines


def test_natural_quintic_reproduces_quadratics() -> None:
    t = np.sort(np.random.default_rng(3).uniform(0, 1, 25))
    y = np.c_[2 + 3 * t - 4 * t**2, t**2]
    ref = ReferenceSplines(t, ("a", "b"), y)
    q = np.linspace(t[0], t[-1], 9)
    assert np.allclose(ref.values(q, 0, ["a"]).ravel(), 2 + 3 * q - 4 * q**2)
    assert np.allclose(ref.values(q, 1, ["a"]).ravel(), 3 - 8 * q)
    assert np.allclose(ref.values(q, 2, ["b"]).ravel(), 2.0)


def test_symbolic_values_and_derivative_in_final_time() -> None:
    t = np.linspace(0, 0.3, 40)
    y = np.c_[np.sin(10 * t)]
    ref = ReferenceSplines(t, ("a",), y)
    tf = cs.MX.sym("tf")
    s = np.array([0.1, 0.5, 0.9])
    expr = ref.symbolic(cs.DM(s) * tf, 0)
    f = cs.Function("f", [tf], [expr, cs.jacobian(expr, tf)])
    value, jac = f(0.3)
    assert np.allclose(np.array(value).ravel(), ref.values(s * 0.3).ravel(), atol=1e-7)
    assert np.allclose(np.array(jac).ravel(), s * ref.values(s * 0.3, 1).ravel(), rtol=1e-4)


def test_bad_time_column() -> None:
    with pytest.raises(InputError, match="strictly increasing"):
        ReferenceSplines(np.array([0, 1, 1, 2.0]), ("a",), np.zeros((4, 1)), source="x.sto")

"""nmsm.core.threads.thread_map: the serial map's values, sparsity and derivatives."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.threads import thread_map


def _frame_function() -> cs.Function:
    x = cs.SX.sym("x", 3)
    p = cs.SX.sym("p", 2)
    y = cs.vertcat(cs.sin(x[0]) * p[0], x[1] * x[2] + p[1] ** 2, cs.exp(-x[2] * p[0]))
    return cs.Function("frame", [x, p], [y, cs.jacobian(y, x)], ["x", "p"], ["y", "dy_dx"])


@pytest.mark.parametrize("threads", [1, 2, 3])
@pytest.mark.parametrize("n", [1, 2, 7])
def test_thread_map_gives_the_serial_map(threads: int, n: int) -> None:
    f = _frame_function()
    mapped = thread_map(f, n, shared=(1,), threads=threads)
    serial = f.map("serial", "serial", n, [1], [])
    rng = np.random.default_rng(n + 10 * threads)
    x, p = rng.normal(size=(3, n)), rng.normal(size=2)
    assert mapped.size_in(0) == (3, n) and mapped.size_in(1) == (2, 1)
    assert mapped.name_in() == ["x", "p"] and mapped.name_out() == ["y", "dy_dx"]
    for ours, theirs in zip(mapped(x, p), serial(x, p)):
        assert ours.sparsity() == theirs.sparsity()
        np.testing.assert_array_equal(np.array(ours), np.array(theirs))


def test_thread_map_of_a_single_output_function() -> None:
    x = cs.SX.sym("x", 2)
    f = cs.Function("square", [x], [x * x])
    np.testing.assert_array_equal(np.array(thread_map(f, 3)(np.arange(6.0).reshape(2, 3))),
                                  np.arange(6.0).reshape(2, 3) ** 2)


def test_thread_map_derivatives_include_the_shared_input() -> None:
    f = _frame_function()
    n = 5
    x, p = cs.MX.sym("x", 3, n), cs.MX.sym("p", 2)
    ours = cs.jacobian(thread_map(f, n, shared=(1,), threads=2)(x, p)[0], cs.vertcat(cs.vec(x), p))
    theirs = cs.jacobian(f.map("serial", "serial", n, [1], [])(x, p)[0], cs.vertcat(cs.vec(x), p))
    jacobians = cs.Function("jacobians", [x, p], [ours, theirs])
    rng = np.random.default_rng(3)
    a, b = jacobians(rng.normal(size=(3, n)), rng.normal(size=2))
    assert np.abs(np.array(b)[:, -2:]).max() > 0.1  # the shared input's columns are not empty
    np.testing.assert_allclose(np.array(a), np.array(b), rtol=0, atol=1e-14)

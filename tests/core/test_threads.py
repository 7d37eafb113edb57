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


# ---- the BLAS of CasADi's IPOPT and MUMPS (limit_solver_blas_threads) -----------------------
@pytest.fixture
def casadi_blas():
    import ctypes
    from pathlib import Path

    library = Path(cs.__file__).parent / "libcasadi-tp-openblas.so.0"
    if not library.is_file():
        pytest.skip("this CasADi build has no bundled OpenBLAS")
    blas = ctypes.CDLL(str(library))
    before = blas.openblas_get_num_threads()
    yield blas
    blas.openblas_set_num_threads(before)


def test_solver_blas_on_one_thread_unless_the_user_chose(casadi_blas, monkeypatch) -> None:
    from nmsm.core.threads import BLAS_THREAD_VARIABLES, limit_solver_blas_threads

    for name in BLAS_THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    casadi_blas.openblas_set_num_threads(2)
    assert limit_solver_blas_threads() == 1
    assert casadi_blas.openblas_get_num_threads() == 1
    casadi_blas.openblas_set_num_threads(2)
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "2")
    assert limit_solver_blas_threads() == 2
    assert casadi_blas.openblas_get_num_threads() == 2


def test_an_ipopt_solve_runs_its_blas_on_one_thread(casadi_blas, monkeypatch) -> None:
    from nmsm.core.problem import OptimizationProblem
    from nmsm.core.threads import BLAS_THREAD_VARIABLES

    for name in BLAS_THREAD_VARIABLES:
        monkeypatch.delenv(name, raising=False)
    casadi_blas.openblas_set_num_threads(2)
    prob = OptimizationProblem()
    x = prob.variable("x", np.zeros(3), lower=-1, upper=1)
    prob.add_cost("fit", x - 0.5)
    assert prob.solve("ipopt", print_level=0).success
    assert casadi_blas.openblas_get_num_threads() == 1

"""Ctrl-C (SIGINT) during an IPOPT solve stops the run (nmsm.core.interrupts).

The objective calls a CasADi callback that, at its third evaluation, waits for a SIGINT sent
by a child process, so the signal always arrives while IPOPT runs.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import casadi as cs
import numpy as np
import pytest

from nmsm.core.problem import OptimizationProblem

pytestmark = [
    pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals"),
    pytest.mark.usefixtures("default_sigint"),  # also when pytest runs in the background (SIGINT ignored)
]


class _WaitsForSigint(cs.Callback):
    """``sum((x - 3)^2)``; the third evaluation sends SIGINT to this process and waits for it."""

    def __init__(self, n: int) -> None:
        cs.Callback.__init__(self)
        self.n = n
        self.calls = 0
        self.construct("waits_for_sigint", {"enable_fd": True})

    def get_n_in(self) -> int:
        return 1

    def get_n_out(self) -> int:
        return 1

    def get_sparsity_in(self, i: int) -> cs.Sparsity:
        return cs.Sparsity.dense(self.n, 1)

    def eval(self, arg):  # noqa: ANN001 - CasADi's signature
        self.calls += 1
        if self.calls == 3:
            subprocess.Popen(["sh", "-c", f"sleep 0.2; kill -INT {os.getpid()}"])
            deadline = time.monotonic() + 30.0
            while time.monotonic() < deadline:  # interrupted by the signal
                time.sleep(0.01)
        return [cs.sumsqr(arg[0] - 3.0)]


def _solve(callback: _WaitsForSigint):
    problem = OptimizationProblem("interrupted")
    x = problem.variable("x", np.ones(callback.n), lower=-10.0, upper=10.0)
    problem.add_cost("slow", cs.sqrt(callback(x)))
    return problem.solve("ipopt", print_level=0, hessian="limited-memory")


def test_casadi_alone_turns_the_interrupt_into_a_solver_status():
    """The behaviour the module guards against (if CasADi changes it, this test says so)."""
    x = cs.MX.sym("x", 3)
    callback = _WaitsForSigint(3)
    solver = cs.nlpsol("s", "ipopt", {"x": x, "f": callback(x)},
                       {"ipopt.print_level": 0, "print_time": False, "ipopt.hessian_approximation": "limited-memory"})
    solver(x0=np.ones(3))
    assert solver.stats()["return_status"] == "NonIpopt_Exception_Thrown"


def test_interrupt_during_ipopt_raises_keyboard_interrupt():
    callback = _WaitsForSigint(3)
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        _solve(callback)
    assert time.monotonic() - start < 10.0
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


def test_a_solve_without_interrupt_is_unchanged():
    problem = OptimizationProblem("plain")
    x = problem.variable("x", np.ones(2), lower=-10.0, upper=10.0)
    problem.add_cost("quadratic", x - 3.0)
    solution = problem.solve("ipopt", print_level=0)
    assert solution.success
    np.testing.assert_allclose(solution["x"].ravel(), [3.0, 3.0], atol=1e-8)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_the_interrupt_tests_pass_when_pytest_starts_with_sigint_ignored():
    """``nohup pytest ... &`` from a non-interactive shell starts pytest with SIGINT ignored
    (SIG_IGN); the ``default_sigint`` fixture gives these tests Python's handler anyway."""
    repo = Path(__file__).resolve().parents[2]
    tests = [f"{Path(__file__).relative_to(repo)}::test_interrupt_during_ipopt_raises_keyboard_interrupt",
             "tests/opensim_bridge/test_opensim_check_stop.py"]
    result = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *tests], cwd=repo,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),
                            capture_output=True, text=True, encoding="utf-8", timeout=600)
    assert result.returncode == 0 and "2 passed" in result.stdout, result.stdout[-3000:] + result.stderr[-2000:]

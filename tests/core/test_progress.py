"""Progress lines of long solves (nmsm.core.progress), through both back ends."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest

from nmsm.core.problem import OptimizationProblem
from nmsm.core.progress import SolveProgress, progress_every

LINE = re.compile(r"^\[progress\] (\w+): iteration (\d+), cost (\S+)(, constraint violation (\S+))?, \d+ s$")


def _constrained() -> OptimizationProblem:
    """min (x-3)^2 + (y-1)^2 subject to x + y = 2 (solution x = 2, y = 0)."""
    problem = OptimizationProblem("constrained_demo")
    x = problem.variable("x", [0.0, 0.0], lower=-10.0, upper=10.0)
    problem.add_cost("distance", x - np.array([3.0, 1.0]))
    problem.add_constraint("sum", x[0] + x[1], 2.0, 2.0)
    return problem


def _lines(text: str) -> list[re.Match[str]]:
    matches = [LINE.match(line) for line in text.splitlines() if line.startswith("[progress]")]
    assert all(matches), text
    return [m for m in matches if m]


def test_ipopt_reports_each_iteration_when_the_interval_is_tiny(capsys):
    with progress_every(1e-9):
        solution = _constrained().solve("ipopt", print_level=0)
    lines = _lines(capsys.readouterr().err)
    assert solution.success
    assert [int(m[2]) for m in lines] == list(range(1, len(lines) + 1))
    assert len(lines) >= solution.iterations  # IPOPT reports iteration 0 too
    assert {m[1] for m in lines} == {"constrained_demo"}
    assert float(lines[-1][3]) == pytest.approx(solution.cost, rel=1e-6)
    assert float(lines[-1][5]) <= 1e-8  # the equality holds at the end


def test_least_squares_reports_its_iterations(capsys, rosenbrock):
    with progress_every(1e-9):
        solution = rosenbrock().solve("least_squares")
    lines = _lines(capsys.readouterr().err)
    assert solution.success and lines
    assert all(m[4] is None for m in lines)  # no constraints: no violation column
    costs = [float(m[3]) for m in lines]
    assert costs[-1] < costs[0]


@pytest.mark.parametrize("backend", ["ipopt", "least_squares"])
def test_silent_without_progress_or_with_zero_interval(capsys, rosenbrock, backend):
    options = {"print_level": 0} if backend == "ipopt" else {}
    rosenbrock().solve(backend, **options)
    with progress_every(0):
        rosenbrock().solve(backend, **options)
    assert "[progress]" not in capsys.readouterr().err


def test_ipopt_log_replaces_progress_lines(capsys):
    """With IPOPT printing its own iteration log, no progress lines are added."""
    with progress_every(1e-9):
        _constrained().solve("ipopt", print_level=5)
    captured = capsys.readouterr()
    assert "[progress]" not in captured.err


def test_lines_are_spaced_by_the_interval():
    stream = io.StringIO()
    progress = SolveProgress("demo", interval=3600.0, stream=stream)
    assert not any(progress.tick() for _ in range(100))  # nothing due within the first hour
    assert progress.iteration == 100
    progress.report(1.5, 2e-3)
    assert stream.getvalue().startswith("[progress] demo: iteration 100, cost 1.5, constraint violation 2.0e-03, ")

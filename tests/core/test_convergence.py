"""Per-iteration histories of the back ends, their table and figure (nmsm.core.convergence,
nmsm.plots.convergence)."""

from __future__ import annotations

from pathlib import Path

import casadi as cs
import numpy as np
import pytest

from nmsm.core.convergence import CONVERGENCE_TABLE, ConvergenceHistory, read_convergence_table, \
    write_convergence_table
from nmsm.core.problem import OptimizationProblem
from nmsm.plots.convergence import plot_histories, plot_results_convergence


def _rosenbrock(constrained: bool) -> OptimizationProblem:
    """min (1 - x)^2 + 100 (y - x^2)^2 from (-1.2, 1); with ``constrained``: x + y = 1.5."""
    problem = OptimizationProblem("rosenbrock")
    v = problem.variable("v", np.array([-1.2, 1.0]), lower=-5.0, upper=5.0)
    problem.add_cost("rosenbrock", cs.vertcat(1 - v[0], 10 * (v[1] - v[0] ** 2)))
    if constrained:
        problem.add_constraint("line", v[0] + v[1], 1.5, 1.5)
    return problem


def test_ipopt_records_every_iterate() -> None:
    solution = _rosenbrock(True).solve("ipopt", print_level=0)
    history = solution.history
    assert solution.success and history is not None
    assert history.n_iterations == solution.iterations + 1  # the start included
    assert history.cost[0] == pytest.approx(24.2) and history.cost[-1] == pytest.approx(solution.cost, rel=1e-9)
    assert history.violation[0] == pytest.approx(1.7) and history.violation[-1] <= 1e-8  # |-1.2 + 1 - 1.5|
    assert history.optimality is not None and history.optimality[-1] <= 1e-6


def test_least_squares_records_each_accepted_iterate() -> None:
    solution = _rosenbrock(False).solve("least_squares")
    history = solution.history
    assert history is not None and history.violation is None
    assert history.cost[0] == pytest.approx(24.2) and history.cost[-1] == pytest.approx(0.0, abs=1e-12)
    # J^T r at the start, r = (2.2, -4.4), in the scaled variable (scale 10: the bound range)
    assert history.optimality[0] == pytest.approx(10 * 107.8)
    assert np.all(np.diff(history.cost) <= 1e-15)  # trust-region steps never increase the cost


def test_table_round_trip_and_figure(tmp_path: Path) -> None:
    histories = {
        "task_1": ConvergenceHistory([10.0, 1.0, 0.1], violation=[0.5, 1e-3, 0.0], optimality=[3.0, 0.2, 1e-7]),
        "task_2": ConvergenceHistory([0.1, 0.05], optimality=[1e-2, 1e-9]),
        "skipped": None,
    }
    write_convergence_table(tmp_path / CONVERGENCE_TABLE, histories)
    back = read_convergence_table(tmp_path / CONVERGENCE_TABLE)
    assert list(back) == ["task_1", "task_2"]
    np.testing.assert_array_equal(back["task_1"].violation, [0.5, 1e-3, 0.0])
    assert back["task_2"].violation is None
    np.testing.assert_array_equal(back["task_2"].optimality, [1e-2, 1e-9])
    figure = plot_results_convergence(tmp_path, tmp_path / "plots", "MTP")
    assert figure == tmp_path / "plots" / "convergence.png" and figure.stat().st_size > 10_000
    assert plot_histories({"none": None}, tmp_path / "x.png", "nothing") is None
    joined = back["task_1"].followed_by(back["task_2"])  # a restarted solve: one history
    np.testing.assert_array_equal(joined.cost, [10.0, 1.0, 0.1, 0.1, 0.05])
    assert joined.violation is None and joined.optimality.size == 5
    with pytest.raises(ValueError, match="violation has 2 iterations, cost 3"):
        ConvergenceHistory([1.0, 2.0, 3.0], violation=[1.0, 2.0])

"""LGR transcription on problems with analytic solutions."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.problem import OptimizationProblem
from nmsm.core.reductions import quadrature
from nmsm.core.transcription.base import Block, FinalTime, Phase
from nmsm.core.transcription.lgr import RadauCollocation
from nmsm.core.transcription.mesh import Mesh


def _double_integrator(mesh: Mesh, final_time: FinalTime) -> tuple[OptimizationProblem, object]:
    x, u, p = cs.SX.sym("x", 2), cs.SX.sym("u", 1), cs.SX.sym("p", 0)
    f = cs.Function("f", [x, u, p], [cs.vertcat(x[1], u)])
    phase = Phase(mesh, Block(("q", "qd"), [-10, -10], [10, 10], np.zeros((mesh.n_nodes, 2))),
                  Block(("qdd",), [-100], [100], np.zeros((mesh.n_collocation, 1))), f, final_time)
    problem = OptimizationProblem("double_integrator")
    traj = RadauCollocation().transcribe(phase, problem)
    problem.add_constraint("start", traj.states("initial"), [0, 0], [0, 0])
    problem.add_constraint("end", traj.states("final"), [1, 0], [1, 0])
    return problem, traj


@pytest.mark.parametrize("intervals,points", [(1, 4), (3, 3), (1, 50)])
def test_minimum_effort_double_integrator(intervals: int, points: int) -> None:
    # x'' = u, x(0) = 0 -> x(1) = 1 at rest, min integral u^2: u = 6 - 12 t, x = 3t^2 - 2t^3
    problem, traj = _double_integrator(Mesh.uniform(intervals, points), FinalTime.fixed(1.0))
    u = traj.controls("collocation")
    problem.add_cost("effort", quadrature(u, traj.quadrature_weights))
    sol = problem.solve("ipopt", print_level=0)
    assert sol.success
    assert sol.cost == pytest.approx(12.0, rel=1e-8)
    out = traj.sample(sol, "nodes")
    t = out["time"]
    assert np.allclose(out["states"][:, 0], 3 * t**2 - 2 * t**3, atol=1e-8)
    assert np.allclose(out["controls"][:, 0], 6 - 12 * t, atol=1e-5)
    fine = traj.sample(sol, np.linspace(0, 1, 33))
    assert np.allclose(fine["states"][:, 1], 6 * fine["time"] - 6 * fine["time"] ** 2, atol=1e-7)


def test_free_final_time() -> None:
    # J = t_f + integral u^2 dt; for fixed t_f the effort is 12/t_f^3, so t_f* = 36^(1/4)
    problem, traj = _double_integrator(Mesh.uniform(2, 4), FinalTime(2.0, 0.5, 5.0))
    u = traj.controls("collocation")
    tf = traj.final_time
    problem.add_cost("effort", quadrature(u, traj.quadrature_weights) * cs.sqrt(tf))
    problem.add_cost("time", cs.sqrt(tf))
    sol = problem.solve("ipopt", print_level=0)
    assert sol.success
    assert traj.sample(sol)["final_time"] == pytest.approx(36 ** 0.25, rel=1e-6)


def test_guess_shape_is_checked() -> None:
    mesh = Mesh.uniform(2, 2)
    x, u, p = cs.SX.sym("x", 2), cs.SX.sym("u", 1), cs.SX.sym("p", 0)
    f = cs.Function("f", [x, u, p], [cs.vertcat(x[1], u)])
    with pytest.raises(ValueError, match="state guess"):
        Phase(mesh, Block(("q", "qd"), -1, 1, np.zeros((3, 2))), Block(("u",), -1, 1, np.zeros((4, 1))), f,
              FinalTime.fixed(1))

"""Treatment at scale: the Hessian keeps one block per point with optimized synergy vectors,
a starting point far from dynamic consistency names its worst constraint row, and Ctrl-C
keeps the last iterate with a diagnosis."""

from __future__ import annotations

import os
import signal
import warnings
from pathlib import Path

import casadi as cs
import numpy as np
import pytest

import nmsm.core.backends.ipopt as backend
from nmsm.tools.treatment.diagnosis import worst_constraint
from nmsm.tools.treatment.run import run_settings

TORQUE_TO = "treatment/torque_kick_tutorial/CompletedSettingsFiles/TorqueTOSettingsV1.xml"
SYNERGY_TO = "treatment/synergy_kick_tutorial/CompletedSettingsFiles/SynergyTOSettingsV4.xml"


def _evaluate(settings: Path, **options: object):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_settings(settings, evaluate_only=True, print_level=0, **options)


def test_optimized_synergy_vectors_do_not_couple_every_point_in_the_hessian(shared_data: Path) -> None:
    run = _evaluate(shared_data / SYNERGY_TO)
    problem = run.prepared.built.problem
    x = problem.scaled_vector()
    g, _, _ = problem.constraint_vector()
    lam = cs.MX.sym("lam", g.numel())
    hessian = cs.hessian(problem.objective() + cs.dot(lam, g), x)[0].sparsity()
    weights, states = problem.variables["synergy_weights"], problem.variables["states"]
    rows, cols = np.array(hessian.row()), np.array(hessian.get_col())
    in_weights = (cols >= weights.start) & (cols < weights.start + weights.size)
    in_states = (rows >= states.start) & (rows < states.start + states.size)
    assert not np.any(in_weights & in_states), "synergy vectors and states share Hessian entries"
    # the same objective at the starting point as the product C W it replaces
    start = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    lifted = [c for c in problem.constraints if c.name.startswith("lifted:")]
    assert lifted and np.max(np.abs(problem.evaluate(lifted[0].expression, start))) < 1e-12


def test_the_worst_constraint_row_of_a_start_names_its_state_and_point(shared_data: Path) -> None:
    run = _evaluate(shared_data / TORQUE_TO)
    built = run.prepared.built
    problem = built.problem
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    states = problem.variables["states"]
    column = list(built.trajectory.phase.states.names).index("knee_angle_r")
    node = 17
    x = x0.copy()
    x[states.start + column * states.shape[0] + node] += 1.0  # a jump of the knee angle at one node
    worst = worst_constraint(built, x)
    assert worst.block.endswith("dynamics_defects")
    assert "state 'knee_angle_r'," in worst.where
    point = int(worst.where.split("collocation point ")[1].split(" ")[0])
    assert abs(point - (node + 1)) <= 1
    assert worst.violation > worst_constraint(built, x0).violation


def test_ctrl_c_keeps_the_last_iterate_and_a_diagnosis(shared_data: Path, tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch, default_sigint) -> None:
    original = backend._IterateCallback.eval

    def stop_at_third(self, arg):  # a SIGINT arriving during iteration 3
        out = original(self, arg)
        if self.iterations == 3:
            os.kill(os.getpid(), signal.SIGINT)
        return out

    monkeypatch.setattr(backend._IterateCallback, "eval", stop_at_third)
    results = tmp_path / "results"
    with warnings.catch_warnings(), pytest.raises(KeyboardInterrupt):
        warnings.simplefilter("ignore")
        run_settings(shared_data / TORQUE_TO, results_directory=results, print_level=0)
    kept = results / "last_iterate"
    assert (kept / "diagnosis.txt").is_file()
    assert "stopped (Ctrl-C)" in (kept / "diagnosis.txt").read_text()
    assert any(p.name.endswith("_states.sto") for p in kept.iterdir())
    assert not any(p.name.endswith("_states.sto") for p in results.iterdir())


def test_a_problem_too_big_for_the_memory_names_its_dominant_dimension(tmp_path: Path) -> None:
    from nmsm.errors import InputError
    from nmsm.tools.treatment.memory import MemoryEstimate, check_memory

    settings = tmp_path / "TOSettings.xml"
    many_points = MemoryEstimate(points=4000, states=31, muscles=20, springs=0)
    with pytest.raises(InputError, match=r"grows with the nodes \(4000 collocation points\)") as error:
        check_memory(many_points, settings, available=1.0)
    assert str(settings) in str(error.value) and "setup_mesh_phase_intervals" in str(error.value)
    many_muscles = MemoryEstimate(points=20, states=31, muscles=400, springs=0)
    with pytest.raises(InputError, match=r"grows with the muscles \(400 muscles\)"):
        check_memory(many_muscles, settings, available=1.0)
    many_springs = MemoryEstimate(points=20, states=31, muscles=0, springs=900)
    with pytest.raises(InputError, match=r"grows with the springs \(900 contact springs\)"):
        check_memory(many_springs, settings, available=1.0)
    check_memory(MemoryEstimate(points=100, states=31, muscles=86, springs=0), settings, available=1e3)


def test_run_stops_before_building_when_the_estimate_does_not_fit(shared_data: Path, tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    import nmsm.tools.treatment.memory as memory
    from nmsm.errors import InputError

    monkeypatch.setattr(memory, "available_gigabytes", lambda: 0.01)
    settings = shared_data / TORQUE_TO
    with warnings.catch_warnings(), pytest.raises(InputError, match="the problem needs about") as error:
        warnings.simplefilter("ignore")
        run_settings(settings, results_directory=tmp_path / "results", print_level=0)
    assert str(settings) in str(error.value)
    assert not (tmp_path / "results").exists()
    assert _evaluate(settings).initial_cost >= 0  # evaluating a start builds no solver: not checked

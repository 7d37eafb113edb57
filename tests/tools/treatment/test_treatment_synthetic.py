"""TO, VO and DO formulations on a pendulum with consistent synthetic data."""

from __future__ import annotations

import numpy as np

from nmsm.constraints.treatment.dynamics import KineticConsistency
from nmsm.constraints.treatment.terminal import (
    FinalMarkerVelocityValue,
    InitialGeneralizedCoordinateDeviation,
    InitialGeneralizedSpeedDeviation,
)
from nmsm.terms.treatment.controllers import ControllerTracking
from nmsm.terms.treatment.inverse_dynamics import InverseDynamicsLoadTracking
from nmsm.terms.treatment.kinematics import GeneralizedCoordinateTracking
from nmsm.core.splines import ReferenceSplines
from nmsm.tools.treatment.solution import TreatmentSolution

from treatment_pendulum_case import DURATION, build_case, reference_data

STATES = ("q0", "q1")


def _to_terms(consistency: float = 0.1):
    terms = [GeneralizedCoordinateTracking(coordinate=c, max_allowable_error=0.05) for c in STATES]
    terms += [InverseDynamicsLoadTracking(load=f"{c}_moment", max_allowable_error=2.0) for c in STATES]
    terms += [KineticConsistency(load=f"{c}_moment", max_error=consistency, min_error=-consistency) for c in STATES]
    return terms


def test_tracking_recovers_the_motion_and_loads() -> None:
    built = build_case(_to_terms(), guess_scale=0.8)
    sol = built.problem.solve("ipopt", print_level=0, tol=1e-10)
    assert sol.success
    out = TreatmentSolution(built, sol, "synthetic")
    coords, loads = reference_data(built.data.model)
    t = out.time
    assert np.max(np.abs(out.positions[:, :2] - coords.values(t, 0, STATES))) < 2e-4
    # torque controls reproduce the loads within the kinetic-consistency bounds
    tau = out.inverse_dynamics[:-1, :2]
    controls = np.hstack([out.control(f"torque:{c}") for c in STATES])[:-1]
    assert np.max(np.abs(tau - controls)) <= 0.1 + 1e-6
    assert np.max(np.abs(tau - loads.values(t[:-1], 0, ["q0_moment", "q1_moment"]))) < 0.05


def test_verification_reproduces_tracking_from_its_controls() -> None:
    # tight kinetic consistency in both, so the controls determine the motion
    built = build_case(_to_terms(1e-3), guess_scale=0.8)
    to = TreatmentSolution(built, built.problem.solve("ipopt", print_level=0, tol=1e-10), "to")
    s = to.view.normalized_time
    torque = ReferenceSplines(s * DURATION, tuple(STATES), np.hstack([to.control(f"torque:{c}") for c in STATES]))
    _, loads = reference_data(built.data.model)
    vo_terms = [ControllerTracking(controller=c, max_allowable_error=1.0) for c in STATES]
    vo_terms += [KineticConsistency(load=f"{c}_moment", max_error=1e-3, min_error=-1e-3) for c in STATES]
    vo_terms += [InitialGeneralizedCoordinateDeviation(coordinate=c, max_error=1e-4, min_error=-1e-4) for c in STATES]
    vo_terms += [InitialGeneralizedSpeedDeviation(coordinate=c, max_error=1e-3, min_error=-1e-3) for c in STATES]
    vo = build_case(vo_terms, tool="VO", guess_scale=0.95, initial_guess={"torqueControls": torque, "loads": loads})
    vo_sol = vo.problem.solve("ipopt", print_level=0, tol=1e-8)
    assert vo_sol.success
    out = TreatmentSolution(vo, vo_sol, "vo")
    assert np.degrees(np.max(np.abs(out.positions[:, :2] - to.positions[:, :2]))) < 0.1
    assert np.max(np.abs(out.inverse_dynamics[:-1, :2] - to.inverse_dynamics[:-1, :2])) < 0.1
    assert vo_sol.iterations < 0.5 * to.solution.iterations or vo_sol.iterations <= 10


def test_design_optimization_with_free_final_time_meets_a_terminal_goal() -> None:
    coords, loads = reference_data(__import__("nmsm.examples.pendulum", fromlist=["Pendulum"]).Pendulum(n=2, coupler_ratio=0.3))
    terms = [ControllerTracking(controller=c, max_allowable_error=5.0) for c in STATES]
    terms += [KineticConsistency(load=f"{c}_moment", max_error=0.1, min_error=-0.1) for c in STATES]
    terms += [FinalMarkerVelocityValue(marker="tip_1", axis="x", min_error=-3.2, max_error=-3.0)]
    built = build_case(terms, tool="DO", guess_scale=1.0, final_time=(0.7, 1.3), initial_guess={"loads": loads})
    sol = built.problem.solve("ipopt", print_level=0, tol=1e-8)
    assert sol.success
    out = TreatmentSolution(built, sol, "do")
    velocity = out.value(built.context.final.marker_velocity("tip_1"))[0, 0]
    assert -3.2 - 1e-6 <= velocity <= -3.0 + 1e-6
    assert 0.7 - 1e-9 <= out.final_time <= 1.3 + 1e-9


def test_periodicity_with_left_right_mapping() -> None:
    from nmsm.constraints.treatment.terminal import GeneralizedCoordinatePeriodicity

    term = GeneralizedCoordinatePeriodicity(coordinate="q0", pair_coordinate="q1", min_error=-0.01, max_error=0.01)
    built = build_case(_to_terms() + [term], guess_scale=1.0)
    sol = built.problem.solve("ipopt", print_level=0, tol=1e-8)
    assert sol.success
    out = TreatmentSolution(built, sol, "periodic")
    q = out.positions
    assert abs(q[-1, 0] - q[0, 1]) <= 0.01 + 1e-6
    # without the mapping the tracked motion ends far from the paired start
    coords, _ = reference_data(built.data.model)
    assert abs(coords.values([DURATION], 0, ["q0"])[0, 0] - coords.values([0.0], 0, ["q1"])[0, 0]) > 0.05

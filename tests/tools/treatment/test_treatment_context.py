"""The treatment context: quantities on grids, laziness, name checks (pendulum model)."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.constraints.treatment.dynamics import KineticConsistency
from nmsm.errors import InputError
from nmsm.examples.pendulum import Pendulum
from nmsm.terms.treatment.kinematics import GeneralizedCoordinateTracking
from nmsm.terms.treatment.markers import MarkerPositionTracking

from treatment_pendulum_case import DURATION, build_case, reference_data


def _at_guess(built, expression):
    problem = built.problem
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    return np.asarray(problem.evaluate(cs.MX(expression), x0))


def test_quantities_match_the_model_at_the_guess() -> None:
    model = Pendulum(n=2, coupler_ratio=0.3)
    built = build_case([GeneralizedCoordinateTracking(coordinate="q0")], model=model, guess_scale=1.0)
    ctx = built.context
    view = ctx.at("nodes")
    q = _at_guess(built, view.positions())
    qd = _at_guess(built, view.speeds())
    qdd = _at_guess(built, view.accelerations())
    # the coupled follower = 0.3 sin(q0) with the chain rule
    assert np.allclose(q[:, 2], 0.3 * np.sin(q[:, 0]))
    assert np.allclose(qd[:, 2], 0.3 * np.cos(q[:, 0]) * qd[:, 0])
    tau = _at_guess(built, view.inverse_dynamics())
    assert np.allclose(tau, model.inverse_dynamics(q, qd, qdd), atol=1e-9)
    tip = _at_guess(built, view.marker_position("tip_1"))
    angles = q[:, 0] + q[:, 1]
    expected = 0.5 * np.c_[np.sin(q[:, 0]) + np.sin(angles), -np.cos(q[:, 0]) - np.cos(angles)]
    assert np.allclose(tip[:, :2], expected)
    orientation = _at_guess(built, view.body_orientation("link_1", "xyz"))
    assert np.allclose(orientation[:, 2], angles)
    # at the data, the guess equals the reference: tracking quantities vanish
    assert np.allclose(_at_guess(built, view.tracked_coordinate("q1")), q[:, [1]], atol=1e-9)


def test_model_functions_are_built_only_when_a_term_asks() -> None:
    built = build_case([GeneralizedCoordinateTracking(coordinate="q0")])
    keys = {k[1] if isinstance(k, tuple) and len(k) > 1 else k for k in built.context._q._cache}
    assert "inverse_dynamics" not in keys and "marker" not in keys
    built = build_case([GeneralizedCoordinateTracking(coordinate="q0"),
                        KineticConsistency(load="q0_moment", max_error=0.1, min_error=-0.1)])
    keys = {k[1] for k in built.context._q._cache if isinstance(k, tuple) and len(k) > 1}
    assert "inverse_dynamics" in keys and "marker" not in keys


def test_free_final_time_rescales_prescribed_speeds() -> None:
    # q1 prescribed: with the phase twice as long, its speed halves and acceleration quarters
    built = build_case([GeneralizedCoordinateTracking(coordinate="q0")], states=("q0",), torque=("q0",),
                       final_time=(0.5, 2.0))
    problem = built.problem
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    tf_var = problem.variables["final_time"]
    x0[tf_var.start] = tf_var.to_scaled(np.array([[2.0]]))[0]
    view = built.context.at("nodes")
    qd = np.asarray(problem.evaluate(view.speed("q1"), x0)).ravel()
    coords, _ = reference_data(built.data.model)
    s = view.normalized_time
    assert np.allclose(qd, 0.5 * coords.values(s * DURATION, 1, ["q1"]).ravel())


def test_name_checks_point_at_the_term() -> None:
    with pytest.raises(InputError, match="coordinate 'knee' is not in the model"):
        build_case([GeneralizedCoordinateTracking(coordinate="knee")])
    with pytest.raises(InputError, match="marker 'toe' is not in the model"):
        build_case([MarkerPositionTracking(marker="toe", axis="x")])
    with pytest.raises(InputError, match="axis"):
        build_case([MarkerPositionTracking(marker="tip_0", axis=None)])
    with pytest.raises(InputError, match="actuated by no controller"):
        build_case([KineticConsistency(load="q1_moment")], torque=("q0",))

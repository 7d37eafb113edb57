"""Known answers of the Treatment Optimization terms as the user sees them: the objective
residuals ``sqrt(w_k) ((g_k - c)/e)`` and constraint rows ``(v - mid)/(max - min)`` of each
term, with ``g``/``v`` the catalog's formula (cost-constraint-terms.md §1.3-1.4, §6) written
out independently with numpy, at a point away from the tracked motion, with a final time
other than 1 s and with non-zero error centres and scale factors (so that a wrong sign, a
missing factor or a wrong default changes the value)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, ClassVar

import casadi as cs
import numpy as np
import pytest

from nmsm.constraints.treatment import dynamics, path
from nmsm.controllers.torque import TorqueController
from nmsm.core.plugin_bases import ContactModel
from nmsm.errors import InputError
from nmsm.examples.pendulum import Pendulum
from nmsm.terms.treatment import (angular_momentum, center_of_pressure, controllers, ground_reactions, impulse,
                                  inverse_dynamics, kinematics, markers)
from nmsm.core.bounds import RangeRule, range_bounds
from nmsm.core.controller_setup import ControllerSetup
from nmsm.tools.treatment.formulation import StateSetup, build_problem
from nmsm.tools.treatment.problem_data import TreatmentData
from nmsm.core.splines import ReferenceSplines
from nmsm.core.transcription.mesh import Mesh

from treatment_pendulum_case import DURATION, reference_data

T_FINAL = 1.6  # s: the problems' (fixed) final time, the tracked data last DURATION = 1 s
K_X, F_OFFSET, FY, K_Y = 40.0, 15.0, 500.0, 80.0
REF = np.array([0.05, 0.0, 0.02])  # the plate's reference point, on the floor
FREE_TORQUE = np.array([0.0, 0.7, 0.0])


def _plate(q0: Any, qd0: Any, lib: Any = np) -> tuple[Any, Any]:
    """Contact point and force of the plate (numpy or CasADi): the forward force K_X q̇0 +
    F_OFFSET is not symmetric, so propulsion and braking differ."""
    point = (0.3 * lib.sin(q0), 0 * q0, 0.1 * lib.cos(q0))
    force = (K_X * qd0 + F_OFFSET, FY + K_Y * q0, 0.2 * K_X * qd0)
    return point, force


class SkewPlate(ContactModel):
    """A synthetic contact on ``link_0`` with the closed-form loads of :func:`_plate` and a free
    torque ``FREE_TORQUE``; ground reaction moment about ``REF``."""

    type: ClassVar[str] = ""
    name = "skew"
    load_bodies = ("link_0",)
    force_labels = ("skew_vx", "skew_vy", "skew_vz")
    moment_labels = ("skew_mx", "skew_my", "skew_mz")
    point_labels = ("skew_px", "skew_py", "skew_pz")

    def point_function(self, model: Any) -> cs.Function:
        nq = len(model.coordinate_names)
        q, qd, p = cs.SX.sym("q", nq), cs.SX.sym("qd", nq), cs.SX.sym("p", 0)
        point, force = _plate(q[0], qd[0], cs)
        c, f = cs.vertcat(*point), cs.vertcat(*force)
        moment = cs.cross(c - cs.DM(REF), f) + cs.DM(FREE_TORQUE)
        return cs.Function("skew", [q, qd, p], [cs.vertcat(f, c, cs.DM(FREE_TORQUE)), f, moment, cs.DM(REF)])


def _moment_about_ref(q0: np.ndarray, qd0: np.ndarray) -> np.ndarray:
    point, force = _plate(q0, qd0)
    return np.cross(np.column_stack(point) - REF, np.column_stack(force)) + FREE_TORQUE


def _tracked_reactions(coords: ReferenceSplines) -> ReferenceSplines:
    """The plate's GRF columns on the tracked motion: force, free torque and contact point."""
    t = coords.time
    q0, qd0 = coords.values(t, 0, ["q0"])[:, 0], coords.values(t, 1, ["q0"])[:, 0]
    point, force = _plate(q0, qd0)
    torque = np.tile(FREE_TORQUE, (t.size, 1))
    data = np.column_stack([*force, torque, *point])
    return ReferenceSplines(t, SkewPlate.force_labels + SkewPlate.moment_labels + SkewPlate.point_labels, data)


def _build(terms: list[Any], *, tool: str = "DO", final_time: float = T_FINAL, torque: tuple[str, ...] = ("q0", "q1"),
           contact: bool = True, torque_guess: ReferenceSplines | None = None, mesh: Mesh | None = None) -> Any:
    """The two-link pendulum of ``treatment_pendulum_case`` (tracked data over 1 s, torque
    controls), solved over a fixed ``final_time``, optionally with the plate contact."""
    model = Pendulum(n=2, coupler_ratio=0.3)
    mesh = mesh or Mesh.uniform(4, 5)
    states = ("q0", "q1")
    coords, loads = reference_data(model)
    refs = {"coordinates": coords, "loads": loads}
    if contact:
        refs["ground_reactions"] = _tracked_reactions(coords)
    s_col = mesh.times("collocation")
    guess = {"loads": loads} if torque_guess is None else {"loads": loads, "torqueControls": torque_guess}
    setup = ControllerSetup(tool, model, s_col * DURATION, DURATION, refs, guess)
    data = TreatmentData(tool, model, states, refs, coords, DURATION, final_time, (final_time, final_time))
    data.controllers = [TorqueController.from_settings({"coordinate_list": " ".join(torque)}, setup)]
    if contact:
        data.contact_models = [SkewPlate()]
    t = coords.time
    lo_q, hi_q = range_bounds(coords.values(t, 0, states), RangeRule(2))
    lo_v, hi_v = range_bounds(coords.values(t, 1, states), RangeRule(1.5))
    lo_a, hi_a = range_bounds(coords.values(t, 2, states), RangeRule(1))
    tn = mesh.times("nodes") * DURATION
    x0 = np.hstack([coords.values(tn, 0, states), coords.values(tn, 1, states)])
    ss = StateSetup(np.r_[lo_q, lo_v], np.r_[hi_q, hi_v], lo_a, hi_a, x0, coords.values(s_col * DURATION, 2, states))
    return build_problem(data, mesh, ss, terms)


def _away(built: Any, seed: int = 11, size: float = 0.15) -> np.ndarray:
    """A point of the problem away from the initial guess (the tracked motion), within bounds."""
    problem = built.problem
    x = problem.initial_scaled() + size * np.random.default_rng(seed).standard_normal(problem.n_variables)
    return _lifted_equal(built, np.clip(x, *problem.bounds_scaled()))


def _lifted_equal(built: Any, x: np.ndarray) -> np.ndarray:
    """``x`` with the lifted variables (GridView.lifted) set equal to their expressions."""
    problem = built.problem
    x = np.array(x, dtype=float)
    for constraint in problem.constraints:
        if constraint.name.startswith("lifted:"):
            variable = problem.variables[constraint.name]
            value = variable.from_scaled(x[variable.start:variable.start + variable.size])
            gap = np.asarray(problem.evaluate(constraint.expression, x)).reshape(variable.shape, order="F")
            x[variable.start:variable.start + variable.size] = variable.to_scaled(value - gap)
    return x


def _ev(built: Any, expression: Any, x: np.ndarray) -> np.ndarray:
    return np.asarray(built.problem.evaluate(cs.MX(expression), x))


def _col(built: Any, expression: Any, x: np.ndarray) -> np.ndarray:
    return _ev(built, expression, x).ravel()


def _weights(built: Any) -> np.ndarray:
    """Quadrature weights of the collocation points over normalized time (sum 1)."""
    return np.asarray(built.trajectory.quadrature_weights, dtype=float).ravel()


def _cost(built: Any, term: Any, x: np.ndarray) -> np.ndarray:
    entry = next(c for c in built.problem.costs if c.term == term)
    return _col(built, entry.residuals, x)


def _constraint(built: Any, term: Any, x: np.ndarray) -> np.ndarray:
    entry = next(c for c in built.problem.constraints if c.term == term)
    return _col(built, entry.expression, x)


def _continuous(built: Any, g: np.ndarray, term: Any, *, per_second: bool = False) -> np.ndarray:
    """Residuals of a continuous cost with integrand ``g``: ``sqrt(w_k) (g_k - c)/e``, times
    ``sqrt(t_f)`` when the integral is over time (``normalize_by_final_time`` false)."""
    r = np.sqrt(_weights(built)) * (g - term.error_center) / term.max_allowable_error
    return r * np.sqrt(T_FINAL) if per_second else r


def _path(v: np.ndarray, term: Any) -> np.ndarray:
    """Rows of a path constraint: ``(v - mid)/(max - min)``."""
    return (v - 0.5 * (term.max_error + term.min_error)) / (term.max_error - term.min_error)


# ---- whole body and ground contact --------------------------------------------------------------
def _rod_angular_momentum(q: np.ndarray, qd: np.ndarray, mass: float, length: float) -> np.ndarray:
    """H_z about the centre of mass of a planar chain of uniform rods (independent sums)."""
    start, start_v = np.zeros((q.shape[0], 2)), np.zeros((q.shape[0], 2))
    angle, omega = np.zeros(q.shape[0]), np.zeros(q.shape[0])
    parts = []
    for i in range(q.shape[1]):
        angle, omega = angle + q[:, i], omega + qd[:, i]
        direction = np.c_[np.sin(angle), -np.cos(angle)]
        rate = np.c_[np.cos(angle), np.sin(angle)] * omega[:, None]
        parts.append((start + 0.5 * length * direction, start_v + 0.5 * length * rate, omega.copy()))
        start, start_v = start + length * direction, start_v + length * rate
    com = sum(p[0] for p in parts) / len(parts)
    vcom = sum(p[1] for p in parts) / len(parts)
    return sum(mass * ((c - com)[:, 0] * (v - vcom)[:, 1] - (c - com)[:, 1] * (v - vcom)[:, 0])
               + mass * length**2 / 12 * w for c, v, w in parts)


def test_angular_momentum_minimization_is_h_over_final_time() -> None:
    """Catalog §6: the integrand is H_z/t_f (t_f = 1.6 s here), about error_center."""
    term = angular_momentum.AngularMomentumMinimization(axis="z", error_center=0.05, max_allowable_error=0.3)
    built = _build([term], contact=False)
    x, ctx = _away(built), built.context
    q = _ev(built, cs.horzcat(ctx.coordinate("q0"), ctx.coordinate("q1")), x)
    qd = _ev(built, cs.horzcat(ctx.speed("q0"), ctx.speed("q1")), x)
    model = Pendulum(n=2, coupler_ratio=0.3)
    H = _rod_angular_momentum(q, qd, model.mass, model.length)
    assert np.max(np.abs(H)) > 0.05
    np.testing.assert_allclose(_cost(built, term, x), _continuous(built, H / T_FINAL, term), rtol=1e-10, atol=1e-12)


def test_impulse_goals_integrate_the_forward_force_over_seconds() -> None:
    """Propulsive ∫max(F_x, 0)dt and braking ∫max(-F_x, 0)dt (N·s, t in seconds: t_f = 1.6 s)
    of an asymmetric force F_x = K q̇0 + F_off; ``normalize_by_final_time`` gives the mean force."""
    push = impulse.PropulsiveImpulseGoal(hindfoot_body="link_0", error_center=30.0, max_allowable_error=4.0)
    brake = impulse.BrakingImpulseGoal(hindfoot_body="link_0", error_center=20.0, max_allowable_error=5.0)
    mean = impulse.PropulsiveImpulseGoal(hindfoot_body="link_0", error_center=10.0, max_allowable_error=2.0,
                                         normalize_by_final_time=True)
    built = _build([push, brake, mean])
    x, ctx = _away(built), built.context
    _, (fx, _, _) = _plate(0.0, _col(built, ctx.speed("q0"), x))
    w = _weights(built)
    forward, backward = w @ np.maximum(fx, 0), w @ np.maximum(-fx, 0)
    assert forward > 10 and backward > 10 and abs(forward - backward) > 10  # they differ: braking is no mirror
    for term, value in ((push, T_FINAL * forward), (brake, T_FINAL * backward), (mean, forward)):
        assert abs(term.error_center - value) > 1.0
        np.testing.assert_allclose(_cost(built, term, x), [(value - term.error_center) / term.max_allowable_error],
                                   rtol=1e-10)


def test_ground_reaction_tracking_with_and_without_relative_error() -> None:
    """F_exp - F and M_exp - M (moment about the plate's reference point), each divided by
    max(|ref|, min_reference_value) with use_relative_error (default minimum 1)."""
    terms = [ground_reactions.ExternalForceTracking(force="skew_vx", error_center=3.0, max_allowable_error=20.0),
             ground_reactions.ExternalForceTracking(force="skew_vx", use_relative_error=True, error_center=0.1,
                                                    max_allowable_error=0.5),
             ground_reactions.ExternalForceTracking(force="skew_vz", use_relative_error=True,
                                                    min_reference_value=6.0, max_allowable_error=0.5),
             ground_reactions.ExternalForceTracking(force="skew_vz", use_relative_error=True, error_center=0.2,
                                                    max_allowable_error=0.5),
             ground_reactions.ExternalMomentTracking(moment="skew_mz", error_center=-1.0, max_allowable_error=8.0),
             ground_reactions.ExternalMomentTracking(moment="skew_mx", use_relative_error=True,
                                                     max_allowable_error=0.5)]
    paths = [path.ExternalMomentDeviation(moment="skew_mz", min_error=-5.0, max_error=20.0),
             path.ExternalForceValue(force="skew_vx", min_error=-50.0, max_error=200.0)]
    built = _build(terms + paths)
    x, ctx = _away(built), built.context
    q0, qd0 = _col(built, ctx.coordinate("q0"), x), _col(built, ctx.speed("q0"), x)
    _, force = _plate(q0, qd0)
    moment = _moment_about_ref(q0, qd0)
    modeled = {"skew_vx": force[0], "skew_vz": force[2], "skew_mz": moment[:, 2], "skew_mx": moment[:, 0]}
    tracked = {label: _col(built, ctx.tracked_ground_reaction_force(label), x) for label in ("skew_vx", "skew_vz")}
    for label in ("skew_mz", "skew_mx"):
        tracked[label] = _col(built, ctx.tracked_ground_reaction_moment(label), x)
    # the tracked moment is the plate's on the tracked motion (interpolated GRF data)
    coords = built.data.references["coordinates"]
    s = ctx.normalized_time * DURATION
    on_data = _moment_about_ref(coords.values(s, 0, ["q0"])[:, 0], coords.values(s, 1, ["q0"])[:, 0])
    np.testing.assert_allclose(tracked["skew_mz"], on_data[:, 2], atol=1e-3)
    # the relative error's minimum matters: |F_z,exp| is below 6 N at some points, above 10 N at others
    assert np.any(np.abs(tracked["skew_vz"]) < 6.0) and np.any(np.abs(tracked["skew_vz"]) > 10.0)
    for term in terms:
        label = getattr(term, "force", None) or term.moment
        g = tracked[label] - modeled[label]
        if term.use_relative_error:  # catalog §1.1: min_reference_value defaults to 1
            minimum = 6.0 if label == "skew_vz" and term.error_center == 0 else 1.0
            g = g / np.maximum(np.abs(tracked[label]), minimum)
        np.testing.assert_allclose(_cost(built, term, x), _continuous(built, g, term), rtol=1e-6, atol=1e-9,
                                   err_msg=f"{term.type} {label} relative={term.use_relative_error}")
    # path constraints: deviation = modeled - tracked, value = modeled
    deviation = modeled["skew_mz"] - tracked["skew_mz"]
    np.testing.assert_allclose(_constraint(built, paths[0], x), _path(deviation, paths[0]), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(_constraint(built, paths[1], x), _path(modeled["skew_vx"], paths[1]), rtol=1e-9)


def test_center_of_pressure_tracking_signs_axes_and_relative_error() -> None:
    """CoP - CoP_exp on x and z (modeled CoP about the plate's floor point P: x = P_x + M_z/F̂_y,
    z = P_z - M_x/F̂_y, F̂_y = F_y + sign(F_y)); use_relative_error divides by
    max(|CoP_exp|, min_reference_value), default minimum 1 m."""
    terms = [center_of_pressure.CenterOfPressureTracking(hindfoot_body="link_0", axis="x", time_ranges=(0.0, 1.0),
                                                          error_center=0.01, max_allowable_error=0.05),
             center_of_pressure.CenterOfPressureTracking(hindfoot_body="link_0", axis="z", time_ranges=(0.2, 0.7),
                                                          error_center=-0.02, max_allowable_error=0.05),
             center_of_pressure.CenterOfPressureTracking(hindfoot_body="link_0", axis="x", time_ranges=(0.0, 1.0),
                                                          use_relative_error=True, max_allowable_error=0.05),
             center_of_pressure.CenterOfPressureTracking(hindfoot_body="link_0", axis="z", time_ranges=(0.0, 1.0),
                                                          use_relative_error=True, min_reference_value=0.09,
                                                          max_allowable_error=0.5)]
    built = _build(terms)
    x, ctx = _away(built), built.context
    q0, qd0 = _col(built, ctx.coordinate("q0"), x), _col(built, ctx.speed("q0"), x)
    _, force = _plate(q0, qd0)
    moment = _moment_about_ref(q0, qd0)
    fy = force[1] + np.where(force[1] >= 0, 1.0, -1.0)
    modeled = {"x": REF[0] + moment[:, 2] / fy, "z": REF[2] - moment[:, 0] / fy}
    tracked_cop = _ev(built, ctx.tracked_center_of_pressure("link_0"), x)
    tracked = {"x": tracked_cop[:, 0], "z": tracked_cop[:, 2]}
    assert np.any(np.abs(tracked["z"]) < 0.09) and np.any(np.abs(tracked["z"]) > 0.09)
    s = ctx.normalized_time
    for term in terms:
        g = modeled[term.axis] - tracked[term.axis]
        if term.use_relative_error:  # catalog §1.1: min_reference_value defaults to 1 (m)
            g = g / np.maximum(np.abs(tracked[term.axis]), 0.09 if term.axis == "z" else 1.0)
        inside = (s >= term.time_ranges[0] - 1e-12) & (s <= term.time_ranges[1] + 1e-12)
        np.testing.assert_allclose(_cost(built, term, x), _continuous(built, g, term) * inside, rtol=1e-9, atol=1e-12,
                                   err_msg=f"{term.axis} relative={term.use_relative_error}")


# ---- controllers ------------------------------------------------------------------------------
def _linear_torques() -> ReferenceSplines:
    """An initial guess of torque controls linear in time: u_q0 = 2 + 3 t, u_q1 = -1 + 0.5 t."""
    t = np.linspace(0, DURATION, 31)
    return ReferenceSplines(t, ("q0", "q1"), np.column_stack([2 + 3 * t, -1 + 0.5 * t]))


def test_controller_costs_on_known_controls() -> None:
    """controller_tracking u - scale·u_init, controller_minimization u, controller_shape_tracking
    u_init - k u (k = u·u_init/u·u) and controller_slope_minimization du/dt in 1/s, integrated
    over seconds by default (normalize_by_final_time false)."""
    tracking = controllers.ControllerTracking(controller="q0", scale_factor=0.5, error_center=0.2,
                                              max_allowable_error=2.0)
    minimum = controllers.ControllerMinimization(controller="q1", error_center=0.3, max_allowable_error=4.0)
    shape = controllers.ControllerShapeTracking(controller="q0", error_center=0.1, max_allowable_error=1.5)
    slope = controllers.ControllerSlopeMinimization(controller="q0", error_center=0.4, max_allowable_error=3.0)
    slope_mean = controllers.ControllerSlopeMinimization(controller="q1", normalize_by_final_time=True,
                                                         max_allowable_error=3.0)
    built = _build([tracking, minimum, shape, slope, slope_mean], contact=False, torque_guess=_linear_torques())
    ctx = built.context
    s = ctx.normalized_time  # the guess's controls are on the data's time s·1 s
    u0_guess, u1_guess = 2 + 3 * s, -1 + 0.5 * s
    # at the initial guess the controls are the linear guess; du/dt = (du/ds)/t_f
    x = built.problem.initial_scaled()
    np.testing.assert_allclose(_col(built, ctx.control("q0"), x), u0_guess, rtol=1e-12)
    np.testing.assert_allclose(_col(built, ctx.control("q1"), x), u1_guess, rtol=1e-12)
    np.testing.assert_allclose(_cost(built, slope, x), _continuous(built, np.full(s.size, 3 / T_FINAL), slope,
                                                                    per_second=True), rtol=1e-9)
    np.testing.assert_allclose(_cost(built, slope_mean, x), _continuous(built, np.full(s.size, 0.5 / T_FINAL),
                                                                         slope_mean), rtol=1e-9)
    # away from the guess
    x = _away(built)
    u0, u1 = _col(built, ctx.control("q0"), x), _col(built, ctx.control("q1"), x)
    assert np.max(np.abs(u0 - u0_guess)) > 0.5
    np.testing.assert_allclose(_cost(built, tracking, x), _continuous(built, u0 - 0.5 * u0_guess, tracking), rtol=1e-10)
    np.testing.assert_allclose(_cost(built, minimum, x), _continuous(built, u1, minimum), rtol=1e-10)
    k = (u0 @ u0_guess) / (u0 @ u0)
    assert abs(k - 1) > 0.05
    np.testing.assert_allclose(_cost(built, shape, x), _continuous(built, u0_guess - k * u0, shape), rtol=1e-9)


# ---- inverse dynamics ---------------------------------------------------------------------------
def _forward_difference(v: np.ndarray, t: np.ndarray) -> np.ndarray:
    return np.r_[np.diff(v) / np.diff(t), 0.0]


def test_inverse_dynamics_costs_on_the_model_loads() -> None:
    """With τ_ID the pendulum's own inverse dynamics of the evaluated kinematics:
    load tracking scale·τ_exp - τ_ID, minimization τ_ID, slope tracking (forward differences in
    seconds, last row 0), shape tracking τ_exp - kτ_ID and the joint power goals, whose
    integrand is (max(±τ_ID q̇ - c, 0)/e)² (catalog §6)."""
    tracking = inverse_dynamics.InverseDynamicsLoadTracking(load="q0_moment", scale_factor=0.5, error_center=0.3,
                                                            max_allowable_error=2.0)
    minimum = inverse_dynamics.InverseDynamicsLoadMinimization(load="q1_moment", error_center=-0.2,
                                                               max_allowable_error=3.0)
    slope = inverse_dynamics.InverseDynamicsSlopeTracking(load="q0_moment", error_center=1.0, max_allowable_error=20.0)
    shape = inverse_dynamics.InverseDynamicsShapeTracking(load="q0_moment", error_center=0.1, max_allowable_error=2.0)
    generation = inverse_dynamics.JointEnergyGenerationGoal(load="q0_moment", error_center=1.5, max_allowable_error=5.0)
    absorption = inverse_dynamics.JointEnergyAbsorptionGoal(load="q0_moment", error_center=0.5, max_allowable_error=5.0)
    terms = [tracking, minimum, slope, shape, generation, absorption]
    built = _build(terms, contact=False)
    x, ctx = _away(built), built.context
    model = built.data.model
    kin = [_ev(built, cs.horzcat(*(f(c) for c in model.coordinate_names)), x)
           for f in (ctx.coordinate, ctx.speed, ctx.acceleration)]
    tau = model.inverse_dynamics(*kin)
    tau0, tau1, qd0 = tau[:, 0], tau[:, 1], kin[1][:, 0]
    exp0 = _col(built, ctx.tracked_load("q0_moment"), x)
    t = ctx.normalized_time * T_FINAL
    k = (tau0 @ exp0) / (tau0 @ tau0)
    assert abs(k - 1) > 0.05
    power = tau0 * qd0
    expected = {
        id(tracking): 0.5 * exp0 - tau0,
        id(minimum): tau1,
        id(slope): _forward_difference(tau0, t) - _forward_difference(exp0, t),
        id(shape): exp0 - k * tau0,
        id(generation): generation.error_center + np.maximum(power - generation.error_center, 0),
        id(absorption): absorption.error_center + np.maximum(-power - absorption.error_center, 0),
    }
    for c in (generation.error_center, absorption.error_center):  # both branches of max(., 0) occur
        assert np.any(power > c) and np.any(power < c) and np.any(-power > c) and np.any(-power < c)
    for term in terms:
        np.testing.assert_allclose(_cost(built, term, x), _continuous(built, expected[id(term)], term), rtol=1e-9,
                                   atol=1e-12, err_msg=term.type)


# ---- kinematic signals, controls and loads: costs and path constraints -----------------------------
def _signal_cases(ctx: Any) -> list[tuple[Any, Any]]:
    """(term, expected g or v as an expression of the context's modeled and tracked signals)."""
    tip_v, tip_p = ctx.marker_velocity("tip_1"), ctx.marker_position("tip_1")
    angles, tracked_angles = ctx.body_orientation("link_1", "xyz"), ctx.tracked_body_orientation("link_1", "xyz")
    bounds = {"min_error": -0.2, "max_error": 0.5}
    return [
        (kinematics.GeneralizedCoordinateTracking(coordinate="q1", error_center=0.05, max_allowable_error=0.2),
         ctx.tracked_coordinate("q1") - ctx.coordinate("q1")),
        (kinematics.GeneralizedSpeedTracking(coordinate="q0", error_center=0.1, max_allowable_error=0.5),
         ctx.tracked_speed("q0") - ctx.speed("q0")),
        (kinematics.GeneralizedSpeedMinimization(coordinate="q1", error_center=0.2, max_allowable_error=0.5),
         ctx.speed("q1")),
        (kinematics.GeneralizedAccelerationTracking(coordinate="q0", error_center=0.3, max_allowable_error=5.0),
         ctx.tracked_acceleration("q0") - ctx.acceleration("q0")),
        (kinematics.GeneralizedAccelerationMinimization(coordinate="q1", error_center=0.4, max_allowable_error=5.0),
         ctx.acceleration("q1")),
        (markers.MarkerPositionTracking(marker="tip_1", axis="y", error_center=0.01, max_allowable_error=0.1),
         ctx.tracked_marker_position("tip_1")[:, 1] - tip_p[:, 1]),
        (markers.MarkerVelocityTracking(marker="tip_1", axis="x", error_center=0.1, max_allowable_error=0.5),
         ctx.tracked_marker_velocity("tip_1")[:, 0] - tip_v[:, 0]),
        (markers.BodyOrientationTracking(body="link_1", axis="z", error_center=0.05, max_allowable_error=0.2),
         angles[:, 2] - tracked_angles[:, 2]),
        (markers.BodyOrientationMinimization(body="link_1", axis="z", error_center=0.1, max_allowable_error=0.2),
         angles[:, 2]),
        (path.GeneralizedCoordinateDeviation(coordinate="q0", **bounds),
         ctx.coordinate("q0") - ctx.tracked_coordinate("q0")),
        (path.GeneralizedSpeedValue(coordinate="q1", **bounds), ctx.speed("q1")),
        (path.GeneralizedAccelerationValue(coordinate="q0", **bounds), ctx.acceleration("q0")),
        (path.GeneralizedAccelerationDeviation(coordinate="q1", **bounds),
         ctx.acceleration("q1") - ctx.tracked_acceleration("q1")),
        (path.MarkerPositionDeviation(marker="tip_1", axis="x", **bounds),
         tip_p[:, 0] - ctx.tracked_marker_position("tip_1")[:, 0]),
        (path.MarkerVelocityDeviation(marker="tip_1", axis="y", **bounds),
         tip_v[:, 1] - ctx.tracked_marker_velocity("tip_1")[:, 1]),
        (path.MarkerVelocityValue(marker="tip_1", axis="x", **bounds), tip_v[:, 0]),
        (path.BodyOrientationDeviation(body="link_1", axis="z", **bounds), angles[:, 2] - tracked_angles[:, 2]),
        (path.ControllerDeviation(controller="q0", scale_factor=0.5, **bounds),
         ctx.control("q0") - 0.5 * ctx.initial_control("q0")),
        (path.ControllerValue(controller="q1", **bounds), ctx.control("q1")),
        (dynamics.KineticConsistency(load="q0_moment", **bounds),
         ctx.inverse_dynamics_load("q0_moment") - ctx.control("q0")),
        (dynamics.RootSegmentResidualLoad(load="q1_moment", **bounds), ctx.inverse_dynamics_load("q1_moment")),
    ]


def test_signal_terms_compute_their_catalog_quantity() -> None:
    """Each tracking cost is ``tracked - modeled`` (body orientation: ``modeled - tracked``),
    each minimization/value the modeled signal, each deviation ``modeled - tracked``, on the
    signal its name says (speed, not position; velocity, not position; ...)."""
    probe = _build([], contact=False)
    terms = [term for term, _ in _signal_cases(probe.context)]
    built = _build(terms, contact=False)
    x = _away(built)
    for term, expression in _signal_cases(built.context):
        v = _col(built, expression, x)
        assert np.ptp(v) > 1e-3, term.type  # a signal that varies: a wrong one would show
        if hasattr(term, "max_allowable_error"):
            np.testing.assert_allclose(_cost(built, term, x), _continuous(built, v, term), rtol=1e-10, atol=1e-12,
                                       err_msg=term.type)
        else:
            np.testing.assert_allclose(_constraint(built, term, x), _path(v, term), rtol=1e-10, atol=1e-12,
                                       err_msg=term.type)


def test_signal_expressions_are_not_interchangeable() -> None:
    """The signals of the previous test differ from each other at the test point (so that a term
    computing a neighbour's signal, e.g. position for velocity, fails there)."""
    built = _build([], contact=False)
    x = _away(built)
    ctx = built.context
    pairs = [(ctx.speed("q0"), ctx.coordinate("q0")), (ctx.acceleration("q1"), ctx.speed("q1")),
             (ctx.marker_velocity("tip_1")[:, 0], ctx.marker_position("tip_1")[:, 0]),
             (ctx.tracked_speed("q0"), ctx.tracked_coordinate("q0")), (ctx.control("q0"), ctx.initial_control("q0"))]
    for a, b in pairs:
        assert np.max(np.abs(_col(built, a, x) - _col(built, b, x))) > 0.1


def test_coordinate_periodicity_needs_a_state_coordinate() -> None:
    """Periodicity of generalized coordinates only on state coordinates (catalog §1.4); speed
    periodicity of a prescribed coordinate is allowed."""
    from nmsm.constraints.treatment.terminal import GeneralizedCoordinatePeriodicity, GeneralizedSpeedPeriodicity

    with pytest.raises(InputError, match="not in <states_coordinate_list>"):
        _build([GeneralizedCoordinatePeriodicity(coordinate="follower", min_error=-1, max_error=1)], contact=False)
    _build([GeneralizedSpeedPeriodicity(coordinate="follower", min_error=-1, max_error=1)], contact=False)


def test_kinetic_consistency_needs_an_actuated_coordinate() -> None:
    with pytest.raises(InputError, match="actuated by no controller"):
        _build([dynamics.KineticConsistency(load="q1_moment", min_error=-1, max_error=1)], contact=False,
               torque=("q0",))


# ---- torque controller --------------------------------------------------------------------------
def test_torque_control_bounds_and_guess() -> None:
    """Bounds: the tracked ID load's [min - R, max + R], R = max(k·range, minimum range), k = 1
    and minimum 0 by default; guess and controller reference: the initial guess's torque
    controls (``<trial>_torqueControls.sto``) when given, else the inverse dynamics."""
    model = Pendulum(n=2, coupler_ratio=0.3)
    coords, loads = reference_data(model)
    mesh = Mesh.uniform(4, 5)
    times = mesh.times("collocation") * DURATION
    tau = loads.values(loads.time, 0, ["q0_moment"])[:, 0]
    low, high, span = tau.min(), tau.max(), np.ptp(tau)

    def controller(settings: dict, guess: dict) -> TorqueController:
        setup = ControllerSetup("TO", model, times, DURATION, {"coordinates": coords, "loads": loads}, guess)
        return TorqueController.from_settings({"coordinate_list": "q0", **settings}, setup)

    plain = controller({}, {"loads": loads}).control_specs()[0]
    assert (plain.lower, plain.upper) == pytest.approx((low - span, high + span), rel=1e-12)
    np.testing.assert_allclose(plain.guess, loads.values(times, 0, ["q0_moment"])[:, 0], rtol=1e-12)
    wide = controller({"torque_controls_range_scale_factor": 0.5, "torque_controls_minimum_range": 3 * span},
                      {"loads": loads}).control_specs()[0]
    assert (wide.lower, wide.upper) == pytest.approx((low - 3 * span, high + 3 * span), rel=1e-12)
    # a load that is 0 throughout (the coupled coordinate's): zero range, so bounds [0, 0] by default
    zero = TorqueController.from_settings({"coordinate_list": "follower"}, ControllerSetup(
        "TO", model, times, DURATION, {"coordinates": coords, "loads": loads}, {"loads": loads})).control_specs()[0]
    assert (zero.lower, zero.upper) == (0.0, 0.0)
    guessed = controller({}, {"loads": loads, "torqueControls": _linear_torques()})
    np.testing.assert_allclose(guessed.control_specs()[0].guess, 2 + 3 * times, rtol=1e-12)
    np.testing.assert_allclose(guessed.control_reference("q0", times).ravel(), 2 + 3 * times, rtol=1e-12)


# ---- muscles and synergies (synergy kicking tutorial) ---------------------------------------------
KICK = ("treatment", "synergy_kick_tutorial")


def _kick(shared: Path, **synergy_settings: Any) -> Any:
    """The tutorial's SynergyTOSettingsV4 (synergy vectors optimized, sum normalization to 1)
    with optional changes of its synergy controller settings."""
    import attrs

    from nmsm.tools.treatment.run import load_settings
    from nmsm.tools.treatment.tool import TreatmentOptions, prepare

    folder = shared.joinpath(*KICK)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(folder / "CompletedSettingsFiles" / "SynergyTOSettingsV4.xml")
        if synergy_settings:
            settings = attrs.evolve(settings, synergy_controller=attrs.evolve(settings.synergy_controller,
                                                                                **synergy_settings))
        return prepare(settings, solver, TreatmentOptions()).built


def _ncp_weights(shared: Path) -> np.ndarray:
    """NCP's synergy vectors (rows) over the tutorial's muscles, as written in the file."""
    from nmsm.io.storage import read_storage

    table = read_storage(shared.joinpath(*KICK, "ncpResults", "synergyWeights.sto"))
    muscles = ("bflh_r", "bfsh_r", "gasmed_r", "glmax2_r", "iliacus_r", "recfem_r", "soleus_r", "tibant_r", "vasmed_r")
    return np.column_stack([table.column(m) for m in muscles])


@pytest.fixture(scope="module")
def kick(shared_data: Path) -> Any:
    return _kick(shared_data)


def _add(built: Any, terms: list[Any]) -> None:
    for term in terms:
        built.problem.add_term(term, built.context)


def test_muscle_activation_terms_and_fiber_length(kick: Any) -> None:
    """muscle_activation_tracking scale·a_exp - a, muscle_activation_minimization with integrand
    (a/e)^p (p = exponent, default 2), muscle_activation_deviation a - scale·a_exp and
    limit_normalized_fiber_length l̃ of the muscle model."""
    from nmsm.terms.treatment.muscles import MuscleActivationMinimization, MuscleActivationTracking

    tracking = MuscleActivationTracking(muscle="recfem_r", scale_factor=0.5, error_center=0.02,
                                        max_allowable_error=0.1)
    cubic = MuscleActivationMinimization(muscle="tibant_r", exponent=3.0, max_allowable_error=0.5)
    square = MuscleActivationMinimization(muscle="bfsh_r", max_allowable_error=0.4)
    deviation = path.MuscleActivationDeviation(muscle="iliacus_r", scale_factor=0.5, min_error=-0.1, max_error=0.3)
    fiber = path.LimitNormalizedFiberLength(muscle="vasmed_r", min_error=0.5, max_error=1.6)
    built = kick
    _add(built, [tracking, cubic, square, deviation, fiber])
    x = np.clip(_away(built, seed=4, size=0.05), *built.problem.bounds_scaled())
    ctx = built.context
    names = ctx.muscle_names
    a = _ev(built, ctx.muscle_activations(), x)
    a_exp = np.column_stack([_col(built, ctx.tracked_muscle_activation(m), x) for m in names])
    w = _weights(built)
    j = names.index
    np.testing.assert_allclose(_cost(built, tracking, x), np.sqrt(w) * (0.5 * a_exp[:, j("recfem_r")]
                               - a[:, j("recfem_r")] - 0.02) / 0.1, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(_cost(built, cubic, x) ** 2, w * (a[:, j("tibant_r")] / 0.5) ** 3, rtol=1e-9, atol=1e-14)
    assert np.max(a[:, j("bfsh_r")]) > 0.05 and np.max(a[:, j("tibant_r")]) > 0.05
    np.testing.assert_allclose(_cost(built, square, x) ** 2, w * (a[:, j("bfsh_r")] / 0.4) ** 2, rtol=1e-9,
                               atol=1e-14)
    np.testing.assert_allclose(_constraint(built, deviation, x),
                               _path(a[:, j("iliacus_r")] - 0.5 * a_exp[:, j("iliacus_r")], deviation), rtol=1e-9)
    # l̃ from the muscle model's point function at the evaluated coordinates and activations
    controller = built.data.controllers[0]
    model = controller.muscle_model
    q = _ev(built, cs.horzcat(*(ctx.coordinate(c) for c in model.coordinates)), x)
    qd = _ev(built, cs.horzcat(*(ctx.speed(c) for c in model.coordinates)), x)
    f = model.point_function()
    p = np.asarray(cs.evalf(model.parameter_row())).ravel()
    rows = [f(q[k], qd[k], a[k], p) for k in range(q.shape[0])]
    l_norm = np.array([np.asarray(r[2]).ravel() for r in rows])
    v_norm = np.array([np.asarray(r[3]).ravel() for r in rows])
    assert np.max(np.abs(l_norm - v_norm)) > 0.1
    np.testing.assert_allclose(_constraint(built, fiber, x), _path(l_norm[:, j("vasmed_r")], fiber), rtol=1e-9)


def test_synergy_vector_terms(kick: Any, shared_data: Path) -> None:
    """Costs: synergy_vector_tracking ‖w - w_init‖ (w_init: NCP's vector normalized to sum 1),
    synergy_vector_symmetry mean(((v1 - v2 - c)/e)²); terminal constraints: sum Σw, magnitude
    ‖w‖ and symmetry softmax(k|v1 - v2|)/k with k = 700/max|w_init| (catalog §1.3-1.4)."""
    from nmsm.constraints.treatment.synergy_vectors import (SynergyVectorMagnitude, SynergyVectorSum,
                                                            SynergyVectorSymmetryConstraint)
    from nmsm.terms.treatment.synergy_vectors import SynergyVectorSymmetry, SynergyVectorTracking

    tracking = SynergyVectorTracking(synergy="RightLeg_2", error_center=0.05, max_allowable_error=0.2)
    symmetry = SynergyVectorSymmetry(synergies=("RightLeg_1", "RightLeg_3"), error_center=0.02,
                                     max_allowable_error=0.1)
    total = SynergyVectorSum(synergy="RightLeg_4", min_error=0.5, max_error=2.0)
    magnitude = SynergyVectorMagnitude(synergy="RightLeg_1", min_error=0.2, max_error=1.0)
    smooth_max = SynergyVectorSymmetryConstraint(synergies=("RightLeg_2", "RightLeg_4"), min_error=0.0,
                                                 max_error=0.4)
    built = kick
    _add(built, [tracking, symmetry, total, magnitude, smooth_max])
    x = _away(built, seed=9, size=0.1)
    ctx = built.context
    W = np.vstack([_col(built, ctx.synergy_vector(f"RightLeg_{k}"), x) for k in range(1, 5)])
    ncp = _ncp_weights(shared_data)
    W0 = ncp / ncp.sum(axis=1, keepdims=True)
    assert np.max(np.abs(W - W0)) > 0.05
    value = np.sqrt(np.sum((W[1] - W0[1]) ** 2) + 1e-12)
    np.testing.assert_allclose(_cost(built, tracking, x), [(value - 0.05) / 0.2], rtol=1e-9)
    z = (W[0] - W[2] - 0.02) / 0.1
    np.testing.assert_allclose(_cost(built, symmetry, x), z / np.sqrt(z.size), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(_constraint(built, total, x), _path(W[3].sum(), total), rtol=1e-9)
    np.testing.assert_allclose(_constraint(built, magnitude, x), _path(np.sqrt(W[0] @ W[0] + 1e-12), magnitude),
                               rtol=1e-9)
    k = 700.0 / np.max(np.abs(np.r_[W0[1], W0[3]]))
    d = np.sqrt((W[1] - W[3]) ** 2 + 1e-12)
    soft = (np.log(np.sum(np.exp(k * d - np.max(k * d)))) + np.max(k * d)) / k
    assert soft == pytest.approx(np.max(d), abs=0.01)
    np.testing.assert_allclose(_constraint(built, smooth_max, x), _path(soft, smooth_max), rtol=1e-9)


@pytest.mark.parametrize("method", ["sum", "magnitude"])
def test_synergy_normalization_keeps_the_activations(shared_data: Path, method: str) -> None:
    """Normalization to a value of 0.5 (tools.md §9): each initial vector's sum (or norm) is 0.5,
    the gauge constraint holds at the start, the commands are multiplied by the same factor
    (guess and controller reference), so the starting activations are NCP's C W."""
    from nmsm.io.storage import read_storage

    built = _kick(shared_data, synergy_vector_normalization_method=method, synergy_vector_normalization_value=0.5,
                  maximum_allowable_synergy_activation=10.0)
    controller = built.data.controllers[0]
    ncp = _ncp_weights(shared_data)
    norms = ncp.sum(axis=1) if method == "sum" else np.linalg.norm(ncp, axis=1)
    factors = norms / 0.5
    W0 = controller.synergy_weight_matrix(initial=True)
    np.testing.assert_allclose(W0, ncp / factors[:, None], rtol=1e-12, atol=1e-15)
    x0 = built.problem.initial_scaled()
    gauge = next(c for c in built.problem.constraints if c.name == "synergy_vector_normalization")
    assert np.max(np.abs(_col(built, gauge.expression, x0))) < 1e-12
    ctx = built.context
    commands = read_storage(shared_data.joinpath(*KICK, "ncpResults", "drive_kick1_synergyCommands.sto"))
    t = ctx.normalized_time * ctx.reference_duration
    names = controller.synergy_names
    C = ReferenceSplines(commands.time, names, np.column_stack([commands.column(n) for n in names])).values(t, 0, names)
    np.testing.assert_allclose(controller.control_reference("RightLeg_3", t).ravel(), C[:, 2] * factors[2], rtol=1e-12)
    assert np.max(C * factors) > 1.0  # above 1: the guess is not clipped to [0, 1]
    activations = _ev(built, ctx.muscle_activations(), x0)
    np.testing.assert_allclose(activations, np.clip(C, 0, None) @ ncp, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(_ev(built, ctx.synergy_weights(), x0), W0, rtol=1e-9, atol=1e-12)


def test_metabolic_cost_per_distance(kick: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    """absolute_metabolic_cost_per_distance P̄/(v + belt speed) (J/m), P̄ = ∫₀¹ Ė ds the mean
    metabolic power and v = (c_x(t_f) - c_x(0))/t_f; the relative version divides by its value
    at the initial guess; the per-time version is P̄ (W)."""
    from nmsm.terms.treatment.metabolic_cost import (AbsoluteMetabolicCostPerDistance, AbsoluteMetabolicCostPerTime,
                                                     RelativeMetabolicCostPerDistance)

    built, ctx = kick, kick.context
    monkeypatch.setattr(ctx, "belt_speed", lambda: 0.8)  # as on a treadmill at 0.8 m/s
    per_distance = AbsoluteMetabolicCostPerDistance(error_center=100.0, max_allowable_error=50.0)
    relative = RelativeMetabolicCostPerDistance(error_center=0.9, max_allowable_error=0.1)
    per_time = AbsoluteMetabolicCostPerTime(error_center=80.0, max_allowable_error=40.0)
    _add(built, [per_distance, relative, per_time])

    def expected(x: np.ndarray) -> tuple[float, float]:
        power = _weights(built) @ _col(built, ctx.metabolic_rate(), x)
        start, end = (_col(built, v.center_of_mass_position()[0, 0], x)[0] for v in (ctx.initial, ctx.final))
        speed = (end - start) / _col(built, ctx.final_time, x)[0]
        assert abs(speed) > 1e-3
        return power, power / (speed + 0.8)

    power0, r0 = expected(built.problem.initial_scaled())
    x = _away(built, seed=5, size=0.05)
    power, r = expected(x)
    assert abs(r / r0 - 1) > 1e-3
    np.testing.assert_allclose(_cost(built, per_distance, x), [(r - 100.0) / 50.0], rtol=1e-9)
    np.testing.assert_allclose(_cost(built, relative, x), [(r / r0 - 0.9) / 0.1], rtol=1e-9)
    np.testing.assert_allclose(_cost(built, per_time, x), [(power - 80.0) / 40.0], rtol=1e-9)


# ---- model functions (DO modifiers) on a recording target ----------------------------------------
class _Target:
    """The part of :class:`~nmsm.tools.treatment.modifiers.ModificationTarget` a modifier uses,
    recording what the modifier sets."""

    def __init__(self, terms: dict[str, tuple[dict[str, str], list[float]]], contacts: list[Any] = ()) -> None:
        from types import SimpleNamespace

        self._terms = {t: (SimpleNamespace(type=t, fields=fields), cs.DM(values))
                       for t, (fields, values) in terms.items()}
        self.settings = SimpleNamespace(parameter_terms=[term for term, _ in self._terms.values()])
        self.contact_models = list(contacts)
        self.strength = {"soleus_r": 3000.0, "tibant_r": 900.0, "gasmed_r": 1500.0}
        self.set: dict[tuple[str, str], float] = {}
        self.scales: dict[str, float] = {}
        self.frames: list[tuple[Any, ...]] = []

    def parameter_term(self, type_name: str) -> Any:
        return self._terms[type_name][0]

    def parameter(self, type_name: str) -> Any:
        return self._terms[type_name][1]

    def error(self, message: str, **kwargs: Any) -> InputError:
        return InputError(message)

    def muscle_parameter(self, muscle: str, name: str) -> float:
        assert name == "max_isometric_force"
        return self.strength[muscle]

    def set_muscle_parameter(self, muscle: str, name: str, value: Any) -> None:
        self.set[(muscle, name)] = float(value)

    def scale_synergy_activation(self, name: str, factor: Any) -> None:
        self.scales[name] = float(factor)

    def set_joint_frame(self, joint: str, frame: str, quantity: str, axes: Any, values: Any) -> None:
        self.frames.append((joint, frame, quantity, list(axes), np.asarray(values).ravel().tolist()))


class _Surface:
    """A contact model with a treadmill belt (the ContactModel belt-speed methods)."""

    def __init__(self, left: bool) -> None:
        self.is_left_foot = left
        self.belt: Any = None

    def belt_speed(self) -> Any:
        return 0.0 if self.belt is None else self.belt  # None: not set by the model function

    def set_belt_speed(self, value: Any) -> None:
        self.belt = float(value)


def test_muscle_parameter_model_functions() -> None:
    """One value per listed muscle (or one shared); ``scaleMaxIsometricForce`` multiplies the
    muscle's force, the ``apply*Parameter`` functions set the named parameter."""
    from nmsm.modifiers import muscle_parameters as mp

    target = _Target({"max_isometric_force_scale": ({"muscle_list": "soleus_r tibant_r"}, [0.5, 0.8]),
                      "optimal_fiber_length": ({"muscle_list": "soleus_r gasmed_r"}, [0.04, 0.06]),
                      "tendon_slack_length": ({"muscle": "tibant_r"}, [0.3]),
                      "max_isometric_force": ({"muscle_list": "soleus_r gasmed_r"}, [2000.0])})
    for cls in (mp.ScaleMaxIsometricForce, mp.ApplyOptimalFiberLengthParameter, mp.ApplyTendonSlackLengthParameter):
        cls().apply(target, {})
    assert target.set == pytest.approx({("soleus_r", "max_isometric_force"): 1500.0,
                                        ("tibant_r", "max_isometric_force"): 720.0,
                                        ("soleus_r", "optimal_fiber_length"): 0.04,
                                        ("gasmed_r", "optimal_fiber_length"): 0.06,
                                        ("tibant_r", "tendon_slack_length"): 0.3}, rel=1e-15)
    mp.ApplyMaxIsometricForceParameter().apply(target, {})
    assert target.set[("soleus_r", "max_isometric_force")] == target.set[("gasmed_r", "max_isometric_force")] == 2000.0


def test_synergy_activation_and_belt_speed_model_functions() -> None:
    """scaleSynergyActivations: one factor per listed synergy (or one shared);
    applyBeltSpeedParameter: the parameter on the surfaces of the foot ``is_left_foot`` names
    (every surface without it)."""
    from nmsm.modifiers.belt_speed import ApplyBeltSpeedParameter
    from nmsm.modifiers.synergy_activation import ScaleSynergyActivations

    target = _Target({"synergy_activation_scale": ({"synergy_list": "RightLeg_1 RightLeg_3"}, [0.6, 0.9])})
    ScaleSynergyActivations().apply(target, {})
    assert target.scales == {"RightLeg_1": 0.6, "RightLeg_3": 0.9}
    shared = _Target({"synergy_activation_scale": ({"synergy": "RightLeg_2 RightLeg_4"}, [0.7])})
    ScaleSynergyActivations().apply(shared, {})
    assert shared.scales == {"RightLeg_2": 0.7, "RightLeg_4": 0.7}
    for side, expected in (("true", [None, 1.25]), ("false", [1.25, None]), ("", [1.25, 1.25])):
        right, left = _Surface(False), _Surface(True)
        fields = {"is_left_foot": side} if side else {}
        ApplyBeltSpeedParameter().apply(_Target({"belt_speed": (fields, [1.25])}, [right, left]), {})
        assert [right.belt, left.belt] == expected, side


def test_joint_frame_model_function_axes_and_frame() -> None:
    """The term's values go to the listed axes in the order written, on the named frame."""
    from nmsm.modifiers.joint_frame import ApplyJointFrameOrientationParameter, ApplyJointFrameTranslationParameter

    target = _Target({"joint_frame_orientation_knee": ({"joint": "knee_r", "frame": "Child", "axes": "z x"},
                                                       [0.1, -0.2]),
                      "joint_frame_translation_hip": ({"joint": "hip_r", "frame": "parent", "axes": "y"}, [0.03])})
    ApplyJointFrameOrientationParameter().apply(target, {})
    ApplyJointFrameTranslationParameter().apply(target, {})
    assert target.frames == [("knee_r", "child", "orientation", [2, 0], [0.1, -0.2]),
                             ("hip_r", "parent", "translation", [1], [0.03])]


# ---- contact models -------------------------------------------------------------------------------
class _Tracked:
    def __init__(self, labels: set[str]) -> None:
        self.labels = labels

    def has(self, label: str) -> bool:
        return label in self.labels


def test_smooth_sphere_foot_groups() -> None:
    """Per-foot groups only when every element ends in _r/_l and the tracked GRF has OpenSim's
    gait columns of every such side; otherwise one model per element ({})."""
    from nmsm.controllers.contact.smooth_sphere import SmoothSphereContact

    names = ["heel_r", "toe_r", "heel_l"]
    both = _Tracked({"ground_force_r_vx", "ground_force_l_vx"})
    assert SmoothSphereContact.foot_groups(names, both) == {"r": (0, 1), "l": (2,)}
    assert SmoothSphereContact.foot_groups(names, _Tracked({"ground_force_r_vx"})) == {}
    assert SmoothSphereContact.foot_groups(names + ["hand"], both) == {}
    assert SmoothSphereContact.foot_groups(names, None) == {}


def test_elastic_foundation_reaction_point_and_moment(shared_data: Path) -> None:
    """GCP's surface (tools.md §6.3, §8.4): the reported point is the midfoot-superior marker
    with y = the resting spring length; the moment is about that marker projected on the floor,
    Σ (p_j - P) × f_j over the springs."""
    from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
    from nmsm.io.osimx import read_osimx
    from nmsm.io.storage import read_storage
    from nmsm.model.foot_contact import CONTACT_PARAMETERS, spring_forces
    from nmsm.tools.treatment.model_adapter import OsimTreatmentModel

    folder = shared_data / "gcp" / "uf_subject3_tutorial"
    model = OsimTreatmentModel(folder / "bodyModel.osim")
    surface = read_osimx(folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").contact_surfaces[0]
    contact = ElasticFoundationContact(surface, model.model, 0)
    ik = read_storage(folder / "preprocessed" / "IKData" / "gait_1.sto")
    ik = ik.to_radians({c for c in model.coordinate_names if model.is_rotational(c)})
    q = ik.columns(model.coordinate_names)[40]
    qd = np.random.default_rng(4).normal(0, 0.3, q.size)
    p = np.asarray(contact.surface.parameters.vector())
    _, force, moment, point = (np.asarray(v).ravel() for v in contact.point_function(model)(q, qd, p))
    cm = model.casadi
    marker = np.asarray(cm.marker_function([contact.surface.midfoot_superior_marker])(q)).ravel()
    resting = p[CONTACT_PARAMETERS.index("resting_spring_length")]
    assert abs(resting) > 1e-4
    np.testing.assert_allclose(point, [marker[0], resting, marker[2]], rtol=1e-12)
    positions = np.column_stack([np.asarray(cm.point_function(b)(q, cs.DM(loc))).ravel()
                                 for b, loc in zip(contact.surface.spring_bodies, contact.surface.spring_locations)])
    velocities = np.column_stack([np.asarray(cm.point_velocity_function(b)(q, qd, cs.DM(loc))).ravel()
                                  for b, loc in zip(contact.surface.spring_bodies, contact.surface.spring_locations)])
    forces = np.asarray(spring_forces(cs.DM(positions), cs.DM(velocities), cs.DM(contact.surface.spring_constants),
                                      cs.DM(p)))
    floor = np.array([marker[0], 0.0, marker[2]])
    on_floor = positions * np.array([[1.0], [0.0], [1.0]])  # the springs' forces act on the floor
    expected = np.cross((on_floor - floor[:, None]).T, forces.T).sum(axis=0)
    assert force[1] > 50
    np.testing.assert_allclose(moment, expected, rtol=1e-10, atol=1e-9 * np.abs(expected).max())


def test_synergy_activation_scale_and_outputs(shared_data: Path) -> None:
    """A synergy's activation scaled by 0.5 (``scaleSynergyActivations``) halves its share
    c_k w_k of every muscle activation; the written commands, vectors and activations are the
    solution renormalized (vectors' sums = the normalization value, commands times the same
    factor) with unchanged activations C W (tools.md §9)."""
    from types import SimpleNamespace

    from nmsm.tools.treatment.modifiers import ModificationTarget

    def halve_second(problem: Any, data: Any) -> None:
        ModificationTarget(data, None).scale_synergy_activation("RightLeg_2", 0.5)

    plain = _kick(shared_data)
    built = plain
    x = _away(built, seed=8, size=0.1)
    ctx = built.context
    controller = built.data.controllers[0]
    C = _ev(built, cs.horzcat(*(ctx.control(n) for n in controller.synergy_names)), x)
    W = _ev(built, ctx.synergy_weights(), x)
    A = _ev(built, ctx.muscle_activations(), x)
    np.testing.assert_allclose(A, C @ W, rtol=1e-10, atol=1e-14)
    solution = SimpleNamespace(trial_name="kick", control=lambda name: _ev(built, ctx.control(name), x),
                               value=lambda e: _ev(built, e, x))
    tables = controller.output_tables(solution)
    commands, weights, activations = (tables[f][1] for f in ("kick_synergyCommands.sto", "synergyWeights.sto",
                                                              "kick_combinedActivations.sto"))
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(commands, C * W.sum(axis=1)[None, :], rtol=1e-12)
    np.testing.assert_allclose(activations, C @ W, rtol=1e-10, atol=1e-14)
    scaled = _kick_with(shared_data, halve_second)
    A_half = _ev(scaled, scaled.context.muscle_activations(), _lifted_equal(scaled, x))
    np.testing.assert_allclose(A - A_half, 0.5 * np.outer(C[:, 1], W[1]), rtol=1e-9, atol=1e-12)


def _kick_with(shared: Path, declare_extra: Any) -> Any:
    from nmsm.tools.treatment.run import load_settings
    from nmsm.tools.treatment.tool import TreatmentOptions, prepare

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(shared.joinpath(*KICK, "CompletedSettingsFiles", "SynergyTOSettingsV4.xml"))
        return prepare(settings, solver, TreatmentOptions(), declare_extra=declare_extra).built


def test_individual_muscle_controller_bounds_and_fiber_length(shared_data: Path) -> None:
    """The muscle controller (settings given as a mapping, as from Python): activations bounded
    by [minimum_activation = 0.01, 1] by default; limit_normalized_fiber_length is l̃ of its
    muscle model."""
    from nmsm.tools.treatment.run import load_settings
    from nmsm.tools.treatment.tool import TreatmentOptions, prepare

    folder = shared_data.joinpath(*KICK)
    coordinates = "hip_flexion_r hip_adduction_r hip_rotation_r knee_angle_r ankle_angle_r subtalar_angle_r"

    class Settings:
        def __init__(self, settings: Any) -> None:
            self._settings = settings
            self.synergy_controller = None
            self.muscle_controller = {"surrogate_model_coordinate_list": coordinates,
                                      "surrogate_model_data_directory": str(folder / "surrogateData")}

        def __getattr__(self, name: str) -> Any:
            return getattr(self._settings, name)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(folder / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml")
        built = prepare(Settings(settings), solver, TreatmentOptions()).built
    controller = built.data.controllers[0]
    specs = controller.control_specs()
    assert {(s.lower, s.upper) for s in specs} == {(0.01, 1.0)}
    fiber = path.LimitNormalizedFiberLength(muscle="gasmed_r", min_error=0.5, max_error=1.6)
    _add(built, [fiber])
    x = _away(built, seed=2, size=0.05)
    ctx = built.context
    model = controller.muscle_model
    q = _ev(built, cs.horzcat(*(ctx.coordinate(c) for c in model.coordinates)), x)
    qd = _ev(built, cs.horzcat(*(ctx.speed(c) for c in model.coordinates)), x)
    a = _ev(built, ctx.muscle_activations(), x)
    p = np.asarray(cs.evalf(model.parameter_row())).ravel()
    l_norm = np.array([np.asarray(model.point_function()(q[k], qd[k], a[k], p)[2]).ravel() for k in range(len(q))])
    gasmed = l_norm[:, ctx.muscle_names.index("gasmed_r")]
    np.testing.assert_allclose(_constraint(built, fiber, x), _path(gasmed, fiber), rtol=1e-9)


def test_center_of_pressure_divides_by_the_force_pushed_away_from_zero() -> None:
    """Catalog §1.4: ``x = P_x + M_z/F̂_y``, ``z = P_z - M_x/F̂_y`` with ``F̂_y = F_y + sign(F_y)``
    (sign(0) = 1), the same for the numeric (tracked) and the symbolic (modeled) path, for a
    pulling (F_y < 0), a zero and a pushing force."""
    import casadi as cs

    from nmsm.tools.treatment.context import _cop

    point = np.array([[0.1, 0.0, 0.2]] * 3)
    force = np.array([[5.0, -4.0, 1.0], [5.0, 0.0, 1.0], [5.0, 600.0, 1.0]])
    moment = np.array([[3.0, 7.0, 6.0]] * 3)
    f_hat = np.array([-5.0, 1.0, 601.0])
    expected = np.c_[0.1 + 6.0 / f_hat, np.zeros(3), 0.2 - 3.0 / f_hat]
    np.testing.assert_allclose(_cop(point, force, moment), expected, rtol=1e-14)
    symbolic = cs.Function("cop", [], [_cop(cs.MX(cs.DM(point)), cs.MX(cs.DM(force)), cs.MX(cs.DM(moment)))])
    np.testing.assert_allclose(np.asarray(symbolic()["o0"]), expected, rtol=1e-14)


def test_belt_speed_is_the_mean_over_the_surfaces_that_have_one() -> None:
    """``belt_speed`` (used by the per-distance metabolic cost): the mean of the contact
    surfaces' belt speeds, contact models without a belt (no parameters) not counted."""
    from types import SimpleNamespace

    import casadi as cs

    from nmsm.tools.treatment.context import GridView

    def surface(speed: float) -> SimpleNamespace:
        return SimpleNamespace(belt_speed=lambda: speed)

    def sphere() -> SimpleNamespace:
        return SimpleNamespace(name="sphere", belt_speed=lambda: None)

    contacts = [surface(1.2), sphere(), surface(1.6)]
    view = SimpleNamespace(_q=SimpleNamespace(data=SimpleNamespace(contact_models=contacts)))
    assert float(cs.evalf(GridView.belt_speed(view))) == pytest.approx(1.4, rel=1e-14)
    view._q.data.contact_models = [sphere()]
    assert GridView.belt_speed(view) == 0.0

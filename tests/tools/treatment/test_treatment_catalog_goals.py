"""DO catalog goals and centre-of-pressure terms: known answers computed independently with
numpy, and exact derivatives (AD against central differences of the pure functions)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, ClassVar

import casadi as cs
import numpy as np
import pytest

from nmsm.controllers.torque import TorqueController
from nmsm.core.plugin_bases import ContactModel
from nmsm.examples.pendulum import Pendulum
from nmsm.model import hill
from nmsm.terms.treatment.angular_momentum import AngularMomentumMinimization
from nmsm.terms.treatment.center_of_pressure import CenterOfPressureTracking, CenterOfPresssureTracking
from nmsm.terms.treatment.impulse import BrakingImpulseGoal, PropulsiveImpulseGoal
from nmsm.terms.treatment.walking_speed import RelativeWalkingSpeedGoal
from nmsm.constraints.treatment.center_of_pressure import CenterOfPressureDeviation, CenterOfPressureValue
from nmsm.errors import InputError
from nmsm.core.bounds import RangeRule, range_bounds
from nmsm.core.controller_setup import ControllerSetup
from nmsm.tools.treatment.formulation import StateSetup, build_problem
from nmsm.tools.treatment.metabolics import metabolic_point_function
from nmsm.tools.treatment.problem_data import TreatmentData
from nmsm.core.splines import ReferenceSplines
from nmsm.core.transcription.mesh import Mesh

from treatment_pendulum_case import DURATION, reference_data

K_FORCE = 40.0  # N per rad/s: forward force of the synthetic plate
FY = 500.0  # N vertical force
REF_POINT = np.array([0.05, 0.4, 0.02])  # reference point of the plate (y is projected to 0)


def _contact_point(q0: Any) -> Any:
    return 0.3 * np.sin(q0), 0.0, 0.1 * np.cos(q0)


class PlateContact(ContactModel):
    """A synthetic contact on ``link_0``: force (K q̇0, FY, 0) at (0.3 sin q0, 0, 0.1 cos q0), free
    torque (0, 0.7, 0); known answers follow in closed form."""

    type: ClassVar[str] = ""
    name = "plate"
    load_bodies = ("link_0",)
    force_labels = ("plate_vx", "plate_vy", "plate_vz")
    moment_labels = ("plate_mx", "plate_my", "plate_mz")
    point_labels = ("plate_px", "plate_py", "plate_pz")

    def point_function(self, model: Any) -> cs.Function:
        nq = len(model.coordinate_names)
        q, qd, p = cs.SX.sym("q", nq), cs.SX.sym("qd", nq), cs.SX.sym("p", 0)
        c = cs.vertcat(0.3 * cs.sin(q[0]), 0, 0.1 * cs.cos(q[0]))
        force = cs.vertcat(K_FORCE * qd[0], FY, 0)
        torque = cs.DM([0, 0.7, 0])
        ref = cs.DM(REF_POINT)
        loads = cs.vertcat(force, c, torque)
        return cs.Function("plate", [q, qd, p], [loads, force, cs.cross(c - ref, force) + torque, ref])


def _grf_reference(coords: ReferenceSplines) -> ReferenceSplines:
    t = coords.time
    q0, qd0 = coords.values(t, 0, ["q0"])[:, 0], coords.values(t, 1, ["q0"])[:, 0]
    cx, _, cz = _contact_point(q0)
    zeros = np.zeros_like(t)
    data = np.column_stack([K_FORCE * qd0, FY + zeros, zeros, zeros, 0.7 + zeros, zeros, cx, zeros, cz])
    return ReferenceSplines(t, PlateContact.force_labels + PlateContact.moment_labels + PlateContact.point_labels, data)


def _build(terms: list[Any], *, tool: str = "DO", contact: bool = True, mesh: Mesh | None = None) -> Any:
    """The pendulum problem of ``treatment_pendulum_case`` with the plate contact and its GRF data."""
    model = Pendulum(n=2, coupler_ratio=0.3)
    mesh = mesh or Mesh.uniform(4, 6)
    states = ("q0", "q1")
    coords, loads = reference_data(model)
    refs = {"coordinates": coords, "loads": loads, "ground_reactions": _grf_reference(coords)}
    s_col = mesh.times("collocation")
    setup = ControllerSetup(tool, model, s_col * DURATION, DURATION, refs, {"loads": loads})
    data = TreatmentData(tool, model, states, refs, coords, DURATION, DURATION, (DURATION, DURATION))
    data.controllers = [TorqueController.from_settings({"coordinate_list": "q0 q1"}, setup)]
    if contact:
        data.contact_models = [PlateContact()]
    t = coords.time
    lo_q, hi_q = range_bounds(coords.values(t, 0, states), RangeRule(2))
    lo_v, hi_v = range_bounds(coords.values(t, 1, states), RangeRule(1.5))
    lo_a, hi_a = range_bounds(coords.values(t, 2, states), RangeRule(1))
    tn = mesh.times("nodes") * DURATION
    guess = np.hstack([coords.values(tn, 0, states), coords.values(tn, 1, states)])
    ss = StateSetup(np.r_[lo_q, lo_v], np.r_[hi_q, hi_v], lo_a, hi_a, guess, coords.values(s_col * DURATION, 2, states))
    return build_problem(data, mesh, ss, terms)


def _value(built: Any, expression: Any, x: np.ndarray | None = None) -> np.ndarray:
    problem = built.problem
    return np.asarray(problem.evaluate(cs.MX(expression), problem.initial_scaled() if x is None else x))


def _check_gradient(built: Any, expression: Any, shift: float = 0.0) -> None:
    """Exact Jacobian of ``expression`` against central differences along a random direction
    (at the initial guess, moved by ``shift`` x a random vector to avoid kinks of max(., 0))."""
    problem = built.problem
    x0 = problem.initial_scaled() + shift * np.random.default_rng(7).standard_normal(problem.n_variables)
    p = problem.parameter_values()
    f = problem.function(expression)
    jac = cs.Function("j", [problem.scaled_vector(), problem.parameter_vector()],
                      [cs.jacobian(cs.MX(expression), problem.scaled_vector())])
    direction = np.random.default_rng(3).standard_normal(x0.size) * 1e-3
    ad = np.asarray(jac(x0, p)) @ direction
    assert np.all(np.isfinite(ad))
    h = 1e-4
    fd = (np.asarray(f(x0 + h * direction, p)).ravel() - np.asarray(f(x0 - h * direction, p)).ravel()) / (2 * h)
    assert np.allclose(ad, fd, rtol=1e-5, atol=1e-8 * max(1.0, np.max(np.abs(fd))))


def _pendulum_numpy(model: Pendulum, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Independent planar rigid-body sums: centre of mass (n, 2), its velocity, H_z about it."""
    m, L = model.mass, model.length
    start = np.zeros((q.shape[0], 2))
    start_v = np.zeros((q.shape[0], 2))
    angle = np.zeros(q.shape[0])
    omega = np.zeros(q.shape[0])
    centres, velocities, omegas = [], [], []
    for i in range(model.n):
        angle = angle + q[:, i]
        omega = omega + qd[:, i]
        direction = np.c_[np.sin(angle), -np.cos(angle)]
        rate = np.c_[np.cos(angle), np.sin(angle)] * omega[:, None]
        centres.append(start + 0.5 * L * direction)
        velocities.append(start_v + 0.5 * L * rate)
        omegas.append(omega.copy())
        start, start_v = start + L * direction, start_v + L * rate
    com = sum(centres) / model.n
    vcom = sum(velocities) / model.n
    H = sum(m * ((c - com)[:, 0] * (v - vcom)[:, 1] - (c - com)[:, 1] * (v - vcom)[:, 0]) + m * L**2 / 12 * w
            for c, v, w in zip(centres, velocities, omegas))
    return com, vcom, H


# ---- whole body ---------------------------------------------------------------------------------
def test_angular_momentum_and_centre_of_mass_of_the_pendulum() -> None:
    term = AngularMomentumMinimization(axis="z", max_allowable_error=2.0)
    built = _build([term], contact=False)
    ctx = built.context
    q = _value(built, cs.horzcat(ctx.coordinate("q0"), ctx.coordinate("q1")))
    qd = _value(built, cs.horzcat(ctx.speed("q0"), ctx.speed("q1")))
    com, vcom, H = _pendulum_numpy(Pendulum(n=2, coupler_ratio=0.3), q, qd)
    assert np.allclose(_value(built, ctx.center_of_mass_position())[:, :2], com, atol=1e-12)
    assert np.allclose(_value(built, ctx.center_of_mass_velocity())[:, :2], vcom, atol=1e-12)
    modeled = _value(built, ctx.angular_momentum())
    assert np.allclose(modeled[:, 2], H, atol=1e-12) and np.allclose(modeled[:, :2], 0, atol=1e-12)
    assert np.max(np.abs(H)) > 0.05  # the motion has angular momentum
    # the term's quantity is H_z / t_f (catalog §6), t_f = 1 s here
    assert np.allclose(_value(built, term.quantity(ctx)).ravel(), H / DURATION, atol=1e-12)
    _check_gradient(built, built.problem.costs[0].residuals)


def test_single_rod_angular_momentum_is_ml2_over_12_omega() -> None:
    """One link: about its own centre of mass, H = m L²/12 ω (textbook value)."""
    model = Pendulum(n=1, mass=2.0, length=0.8)
    from nmsm.tools.treatment.whole_body import whole_body_function

    f = whole_body_function(model)
    com, vcom, H = (np.asarray(v).ravel() for v in f([0.3], [1.7]))
    assert np.isclose(H[2], 2.0 * 0.8**2 / 12 * 1.7, rtol=1e-14)
    assert np.allclose(com, [0.4 * np.sin(0.3), -0.4 * np.cos(0.3), 0])
    assert np.allclose(vcom, [0.4 * np.cos(0.3) * 1.7, 0.4 * np.sin(0.3) * 1.7, 0])


def test_relative_walking_speed_is_the_mean_forward_com_speed() -> None:
    term = RelativeWalkingSpeedGoal(error_center=0.1, max_allowable_error=0.05)
    built = _build([term], contact=False)
    ctx = built.context
    # the guess is periodic (zero mean speed): evaluate at a perturbed point
    x = built.problem.initial_scaled() + 0.05 * np.random.default_rng(5).standard_normal(built.problem.n_variables)
    q = [_value(built, cs.horzcat(v.coordinate("q0"), v.coordinate("q1")), x) for v in (ctx.initial, ctx.final)]
    zero = np.zeros((1, 2))
    x0, xf = (_pendulum_numpy(Pendulum(n=2), qq, zero)[0][0, 0] for qq in q)
    expected = (xf - x0) / DURATION
    assert abs(xf - x0) > 1e-3
    assert np.isclose(_value(built, term.quantity(ctx), x).item(), expected, rtol=1e-12, atol=1e-14)
    residual = _value(built, built.problem.costs[0].residuals, x).item()
    assert np.isclose(residual**2, ((expected - 0.1) / 0.05) ** 2, rtol=1e-10)
    _check_gradient(built, built.problem.costs[0].residuals)


# ---- ground contact -----------------------------------------------------------------------------
def test_impulses_of_a_known_force_profile() -> None:
    """F_x = K q̇0 with q0 = 0.6 sin(2π t): ∫max(F_x, 0)dt = ∫max(-F_x, 0)dt = 2 K 0.6 over one period."""
    terms = [PropulsiveImpulseGoal(hindfoot_body="link_0", error_center=40.0, max_allowable_error=5.0),
             BrakingImpulseGoal(hindfoot_body="link_0", error_center=40.0, max_allowable_error=5.0)]
    built = _build(terms, mesh=Mesh.uniform(4, 8))  # interval ends at the sign changes (t = 1/4, 3/4)
    ctx = built.context
    expected = 2 * K_FORCE * 0.6
    for term in terms:
        value = _value(built, term.quantity(ctx)).item()
        assert np.isclose(value, expected, rtol=1e-5), (term.type, value, expected)
    for cost in built.problem.costs:  # the guess has F_x = 0 at two collocation points (kinks)
        _check_gradient(built, cost.residuals, shift=0.02)
    # normalize_by_final_time: the mean force (the original's normalized-time integral)
    mean = PropulsiveImpulseGoal(hindfoot_body="link_0", error_center=0.0, normalize_by_final_time=True)
    assert np.isclose(_value(built, mean.quantity(ctx)).item(), expected / DURATION, rtol=1e-5)


def test_impulse_needs_error_center_and_a_foot() -> None:
    with pytest.raises(InputError, match="error_center"):
        _build([PropulsiveImpulseGoal(hindfoot_body="link_0")])
    with pytest.raises(InputError, match="no contact model acts on hindfoot body 'link_1'"):
        _build([BrakingImpulseGoal(hindfoot_body="link_1", error_center=1.0)])


def test_center_of_pressure_known_answer_and_derivatives() -> None:
    terms = [CenterOfPressureTracking(hindfoot_body="link_0", axis=a, time_ranges=(0.0, 1.0), max_allowable_error=0.01)
             for a in "xz"]
    built = _build(terms)
    ctx = built.context
    q0 = _value(built, ctx.coordinate("q0")).ravel()
    cx, _, cz = _contact_point(q0)
    ratio = FY / (FY + 1.0)  # F̂_y = F_y + sign(F_y)
    cop = _value(built, ctx.center_of_pressure("link_0"))
    assert np.allclose(cop[:, 0], REF_POINT[0] + (cx - REF_POINT[0]) * ratio, atol=1e-12)
    assert np.allclose(cop[:, 2], REF_POINT[2] + (cz - REF_POINT[2]) * ratio, atol=1e-12)
    assert np.allclose(cop[:, 1], 0)
    # experimental CoP: the electrical centre (no torque about x, z there)
    t = ctx.normalized_time * DURATION
    coords = built.data.references["coordinates"]
    ex, _, ez = _contact_point(coords.values(t, 0, ["q0"])[:, 0])
    tracked = np.asarray(ctx.tracked_center_of_pressure("link_0"))
    # (the GRF data are splined from splined kinematics: 1e-5 m interpolation error at the ends)
    assert np.allclose(tracked[:, 0], ex, atol=1e-5) and np.allclose(tracked[:, 2], ez, atol=1e-5)
    for cost in built.problem.costs:
        _check_gradient(built, cost.residuals)


def test_center_of_pressure_constraints_and_alias() -> None:
    value = CenterOfPressureValue(hindfoot_body="link_0", axis="x", time_ranges=(0.25, 0.75), min_error=-1, max_error=1)
    deviation = CenterOfPressureDeviation(hindfoot_body="link_0", axis="z", time_ranges=(0.0, 1.0),
                                          min_error=-0.01, max_error=0.01)
    alias = CenterOfPresssureTracking(hindfoot_body="link_0", axis="x", time_ranges=(0.0, 1.0))
    built = _build([value, deviation, alias])
    ctx = built.context
    cop = _value(built, ctx.center_of_pressure("link_0"))
    rows = np.flatnonzero((ctx.normalized_time >= 0.25) & (ctx.normalized_time <= 0.75))
    g_value = _value(built, built.problem.constraints[-2].expression).ravel()
    assert np.allclose(g_value, cop[rows, 0] / 2.0, atol=1e-12)  # (v - mid)/(max - min)
    g_dev = _value(built, built.problem.constraints[-1].expression).ravel()
    tracked = np.asarray(ctx.tracked_center_of_pressure("link_0"))
    assert np.allclose(g_dev, (cop[:, 2] - tracked[:, 2]) / 0.02, atol=1e-9)
    for c in built.problem.constraints[-2:]:
        _check_gradient(built, c.expression)
    assert alias.type == "center_of_presssure_tracking"


def test_center_of_pressure_input_errors() -> None:
    with pytest.raises(InputError, match="time_ranges"):
        _build([CenterOfPressureValue(hindfoot_body="link_0", axis="x")])
    with pytest.raises(InputError, match="floor axis"):
        _build([CenterOfPressureTracking(hindfoot_body="link_0", axis="y", time_ranges=(0.0, 1.0))])


# ---- metabolic model ----------------------------------------------------------------------------
def bhargava_numpy(a: np.ndarray, l_norm: np.ndarray, v_norm: np.ndarray, F0: np.ndarray, lo: np.ndarray,
                   alpha: np.ndarray, vmax: float = 10.0) -> np.ndarray:
    """The smoothed Bhargava (2004) rates (W per muscle) written from spec tools.md §11.2."""
    sigma, rho, b = 610e3, 1059.7, 10.0
    mass = rho * F0 * lo / sigma
    fast = 0.5 * (1 - np.cos(np.pi * a / 2))
    slow = 0.5 * np.sin(np.pi * a / 2)
    fl = hill.active_force_length(l_norm)
    f_ce = F0 * a * fl * hill.force_velocity(v_norm)
    f_iso = f_ce * hill.force_velocity(0.0) / hill.force_velocity(v_norm)
    f_tot = f_ce + F0 * hill.passive_force_length(l_norm)
    activation = mass * (133 * fast + 40 * slow)
    g = np.select([l_norm <= 0.5, l_norm <= 1.0, l_norm <= 1.5], [0.5 + 0 * l_norm, l_norm, 3 - 2 * l_norm], 0.0)
    maintenance = mass * g * (111 * fast + 74 * slow)
    v = v_norm * vmax * lo * np.cos(alpha)
    p = 0.5 + 0.5 * np.tanh(b * v)
    shortening = -((1 - p) * (0.16 * f_iso + 0.18 * f_tot) + p * 0.157 * f_tot) * v
    work = -f_ce * v * (1 - p)
    total = activation + maintenance + shortening + work
    shortening = shortening - total * (0.5 + 0.5 * np.tanh(-b * total))
    x = (activation + maintenance + shortening) / mass
    x = x + (1 - x) * (0.5 + 0.5 * np.tanh(b * (1 - x)))
    return mass * x + work


STATES = [  # (a, l̃, ṽ): each g(l̃) branch, shortening, lengthening, rest
    (0.0, 1.0, 0.0), (0.05, 0.4, -0.3), (0.4, 0.8, -0.2), (0.8, 1.2, 0.15), (1.0, 1.6, 0.5), (0.3, 1.0, -0.9),
]
F0 = np.array([1200.0, 800.0, 3000.0, 450.0, 2000.0, 900.0])
LO = np.array([0.1, 0.08, 0.05, 0.12, 0.09, 0.2])
ALPHA = np.array([0.0, 0.1, 0.3, 0.05, 0.2, 0.0])


def test_bhargava_rates_match_the_published_formulas() -> None:
    a, ln, vn = (np.array(c) for c in zip(*STATES))
    f = metabolic_point_function(len(a))
    params = np.r_[F0, LO, np.cos(ALPHA), np.full(len(a), 10.0)]
    expected = bhargava_numpy(a, ln, vn, F0, LO, ALPHA)
    per_muscle = [float(metabolic_point_function(1)(a[i], ln[i], vn[i], params[i::len(a)])) for i in range(len(a))]
    assert np.allclose(per_muscle, expected, rtol=1e-12)
    assert np.isclose(float(f(a, ln, vn, params)), expected.sum(), rtol=1e-12)
    # a resting muscle costs the 1 W/kg floor: m = ρ F0 l_o / σ
    rest_mass = 1059.7 * F0[0] * LO[0] / 610e3
    assert np.isclose(per_muscle[0], rest_mass * (0.5 + 0.5 * np.tanh(10.0)), rtol=1e-12)
    # shortening costs more than holding the same activation
    hold = float(metabolic_point_function(1)(0.4, 0.8, 0.0, [F0[2], LO[2], np.cos(ALPHA[2]), 10.0]))
    assert per_muscle[2] > hold


def test_bhargava_gradient_matches_central_differences() -> None:
    a, ln, vn = (np.array(c) for c in zip(*STATES))
    a = np.clip(a, 0.02, 0.98)
    M = len(a)
    x = cs.SX.sym("x", 3 * M)
    params = np.r_[F0, LO, np.cos(ALPHA), np.full(M, 10.0)]
    rate = metabolic_point_function(M)(x[:M], x[M:2 * M], x[2 * M:], params)
    f = cs.Function("f", [x], [rate])
    grad = cs.Function("g", [x], [cs.gradient(rate, x)])
    x0 = np.r_[a, ln + 0.013, vn + 0.007]  # away from the kinks of g(l̃) at 0.5, 1, 1.5
    g = np.asarray(grad(x0)).ravel()
    h = 1e-6
    fd = np.array([(float(f(x0 + h * e)) - float(f(x0 - h * e))) / (2 * h) for e in np.eye(3 * M)])
    assert np.all(np.isfinite(g))
    assert np.allclose(g, fd, rtol=1e-6, atol=1e-6 * np.max(np.abs(fd)))


def test_metabolic_goal_needs_muscles() -> None:
    from nmsm.terms.treatment.metabolic_cost import AbsoluteMetabolicCostPerTime

    with pytest.raises(InputError, match="needs muscles"):
        _build([AbsoluteMetabolicCostPerTime()], contact=False)


# ---- metabolic rate on the synergy kicking tutorial (context wiring) --------------------------------
def test_metabolic_rate_of_the_synergy_kick_guess(shared_data: Path) -> None:
    from nmsm.terms.treatment.metabolic_cost import (AbsoluteMetabolicCostPerTime,
                                                     RelativeMetabolicCostPerTime)
    from nmsm.tools.treatment.run import load_settings
    from nmsm.tools.treatment.tool import TreatmentOptions, prepare

    folder = shared_data / "treatment" / "synergy_kick_tutorial"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(folder / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml")
        prepared = prepare(settings, solver, TreatmentOptions())
    built = prepared.built
    ctx = built.context
    x0 = np.clip(built.problem.initial_scaled(), *built.problem.bounds_scaled())

    def at_start(e: Any) -> np.ndarray:
        return np.asarray(built.problem.evaluate(cs.MX(e), x0))

    a = at_start(ctx.muscle_activations())
    ln = at_start(ctx._muscle_quantity("normalized_fiber_length"))
    vn = at_start(ctx._muscle_quantity("normalized_fiber_velocity"))
    from nmsm.model import load_model

    osim = load_model(folder / "KickingModel.osim")
    muscle_model = next(c.muscle_model for c in built.data.controllers if getattr(c, "muscle_model", None))
    F0 = np.array([float(muscle_model.parameters[m]["max_isometric_force"]) for m in ctx.muscle_names])
    lo = np.array([float(muscle_model.parameters[m]["optimal_fiber_length"]) for m in ctx.muscle_names])
    alpha = np.array([osim.muscle(m).pennation_angle_at_optimal for m in ctx.muscle_names])
    body_mass = sum(b.mass for b in osim.bodies.values())
    expected = bhargava_numpy(a, ln, vn, F0[None, :], lo[None, :], alpha[None, :]).sum(axis=1) + 1.2 * body_mass
    rate = at_start(ctx.metabolic_rate()).ravel()
    assert np.allclose(rate, expected, rtol=1e-10)
    assert np.all(rate > 1.2 * body_mass)
    mean = at_start(AbsoluteMetabolicCostPerTime().quantity(ctx)).item()
    w = built.trajectory.quadrature_weights
    assert np.isclose(mean, w @ expected, rtol=1e-10)
    # the relative cost is 1 at the initial guess (the problem's unclipped start point)
    relative = float(np.asarray(built.problem.evaluate(cs.MX(RelativeMetabolicCostPerTime().quantity(ctx)),
                                                       built.problem.initial_scaled())).ravel()[0])
    assert np.isclose(relative, 1.0, rtol=1e-12)
    grad = at_start(cs.gradient(AbsoluteMetabolicCostPerTime().quantity(ctx), built.problem.scaled_vector()))
    assert np.all(np.isfinite(grad)) and np.max(np.abs(grad)) > 0


# ---- a short Design Optimization with a metabolic goal (synergy kicking tutorial) ------------------
METABOLIC_TERM = """<RCNLCostTerm name="metabolic"><is_enabled>true</is_enabled>
 <type>relative_metabolic_cost_per_time</type><max_allowable_error>0.2</max_allowable_error>
 <error_center>0</error_center></RCNLCostTerm>"""


def write_metabolic_do_settings(shared: Path, folder: Path, *, with_goal: bool = True) -> Path:
    """The tutorial's SynergyDOSettingsV1 (same kick: final toe position, speed and foot
    orientation constrained, free final time) with paths made absolute and, with
    ``with_goal``, a ``relative_metabolic_cost_per_time`` goal next to its controller tracking."""
    from lxml import etree

    tutorial = shared / "treatment" / "synergy_kick_tutorial"
    source = tutorial / "CompletedSettingsFiles" / "SynergyDOSettingsV1.xml"
    tree = etree.parse(str(source))
    tool = tree.getroot()[0]
    done = tutorial / "CompletedSettingsFiles" / "SynergyVOResultsV2"
    paths = {"results_directory": folder / "results", "initial_guess_directory": done,
             "tracked_quantities_directory": done, "input_model_file": tutorial / "KickingModel.osim",
             "input_osimx_file": tutorial / "ncpResults" / "KickingModel_ncp.osimx",
             "optimal_control_solver_settings_file": tutorial / "gpopsSettings.xml"}
    for tag, value in paths.items():
        tool.find(tag).text = str(value)
    tool.find("load_surrogate_model").text = "false"
    solver = etree.parse(str(tutorial / "gpopsSettings.xml"))
    gpops = solver.getroot()[0][0]
    gpops.find("setup_mesh_phase_intervals").text = "5"  # 30 points instead of 1 x 50 (a short test)
    gpops.find("setup_mesh_phase_colpoints_per_Interval").text = "6"
    folder.mkdir(parents=True, exist_ok=True)
    solver.write(str(folder / "gpopsSettings.xml"))
    tool.find("optimal_control_solver_settings_file").text = str(folder / "gpopsSettings.xml")
    tool.find("RCNLSynergyController/surrogate_model_data_directory").text = str(tutorial / "surrogateData")
    if with_goal:
        tool.find("RCNLCostTermSet").append(etree.fromstring(METABOLIC_TERM))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / ("MetabolicDOSettings.xml" if with_goal else "TrackingDOSettings.xml")
    tree.write(str(path))
    return path


def test_foot_reaction_of_the_elastic_foundation(shared_data: Path) -> None:
    """GCP tutorial foot at mid stance. The elastic foundation's CoP uses its own moment about the
    midfoot floor point P (GCP's convention, springs' forces on the floor): ``x = P_x + M_z/F̂_y``.
    The moment of the loads it applies at the (penetrating) springs differs from it as by the
    horizontal force acting a few millimetres lower."""
    from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
    from nmsm.io.osimx import read_osimx
    from nmsm.io.storage import read_storage
    from nmsm.tools.treatment.model_adapter import OsimTreatmentModel
    from nmsm.tools.treatment.whole_body import foot_reaction_function

    folder = shared_data / "gcp" / "uf_subject3_tutorial"
    model = OsimTreatmentModel(folder / "bodyModel.osim")
    surface = read_osimx(folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").contact_surfaces[0]
    contact = ElasticFoundationContact(surface, model.model, 0)
    ik = read_storage(folder / "preprocessed" / "IKData" / "gait_1.sto")
    ik = ik.to_radians({c for c in model.coordinate_names if model.is_rotational(c)})
    q = ik.columns(model.coordinate_names)[40]
    qd = np.random.default_rng(2).normal(0, 0.3, q.size)
    p = np.asarray(contact.surface.parameters.vector())
    f = contact.point_function(model)
    _, force, moment, point = (np.asarray(v).ravel() for v in f(q, qd, p))
    F, M_origin, P = (np.asarray(v).ravel() for v in foot_reaction_function(f, moment_about_floor_point=True)(q, qd, p))
    assert force[1] > 50 and np.allclose(F, force)
    assert np.allclose(P, [point[0], 0.0, point[2]])
    assert np.allclose(M_origin - np.cross(P, F), moment, atol=1e-9 * np.abs(force).max())
    _, M_loads, _ = (np.asarray(v).ravel() for v in foot_reaction_function(f)(q, qd, p))
    delta = M_loads - M_origin
    # ΔM = -(0, h, 0) × F: an equivalent height of the horizontal forces below the floor (the
    # springs' penetration), a few millimetres, similar for both axes (springs differ a little)
    h = np.array([-delta[0] / F[2], delta[2] / F[0]])
    assert abs(delta[1]) < 1e-9 * np.abs(force).max()
    assert np.all((h > 0) & (h < 0.02)) and np.isclose(h[0], h[1], rtol=0.05)


@pytest.mark.slow
def test_design_optimization_lowers_the_metabolic_cost_of_the_kick(shared_data: Path, tmp_path: Path) -> None:
    """SynergyDOSettingsV1 (the same kick: final toe position and speed, foot orientation,
    kinetic consistency) plus ``relative_metabolic_cost_per_time`` (error_center 0), started from
    the original's DO V1 solution: the mean metabolic power falls below that solution's while the
    constraints hold."""
    from nmsm.terms.treatment.metabolic_cost import AbsoluteMetabolicCostPerTime
    from nmsm.tools.treatment.run import run_settings

    path = write_metabolic_do_settings(shared_data, tmp_path / "do")
    start = shared_data / "treatment" / "synergy_kick_tutorial" / "CompletedSettingsFiles" / "SynergyDOResultsV1"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_settings(path, results_directory=tmp_path / "do" / "results", guess_directory=start)
    assert run.solution.success, run.summary
    built = run.prepared.built
    power = AbsoluteMetabolicCostPerTime().quantity(built.context)
    before = built.problem.evaluate(cs.MX(power), built.problem.initial_scaled()).item()
    after = built.problem.evaluate(cs.MX(power), run.solution.x_scaled).item()
    g, lo, hi = built.problem.constraint_vector()
    values = built.problem.evaluate(g, run.solution.x_scaled).ravel()
    assert np.all(values >= lo - 1e-4) and np.all(values <= hi + 1e-4)
    print(f"mean metabolic power {before:.2f} W -> {after:.2f} W ({after / before:.3f})")
    assert after < 0.95 * before
    assert (tmp_path / "do" / "results" / "drive_kick1_states.sto").is_file()

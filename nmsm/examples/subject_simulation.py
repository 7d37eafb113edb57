"""The synthetic subject's forward simulation: its recorded gait is made here.

The pelvis, hip adduction, hip rotation and the toes follow the reference (prescribed);
hip flexion, knee and ankle angles are *simulated*: their accelerations come from the
model's mass matrix and inverse dynamics (nmsm's model core) under gravity, the muscles'
forces (:mod:`nmsm.model.hill`, exact path geometry) and the foot-ground springs of Ground
Contact Personalization (:mod:`nmsm.model.foot_contact`).

Muscles are driven by synergies at the activation level, ``a = c W`` (W: S x M, the truth
NCP should recover), with commands ``c >= 0``. Each step a computed-torque controller asks
for the accelerations ``udot_ref + K (q_ref - q) + D (u_ref - u)``; the commands in [0, 1]
whose muscle moments best produce them (bounded least squares, scaled so no activation
exceeds :data:`MAX_ACTIVATION`) are the targets the command state follows with rise and fall
time constants :data:`RISE`, :data:`FALL` (so activations never change faster than the
muscles' activation dynamics allow; the EMG is the excitation that produces them,
:func:`nmsm.examples.subject_data.excitations_from_activations`). So the joint moments of
hip, knee and ankle are exactly the muscles' moments, the ground reactions exactly the
springs' forces.

Design (:func:`design_synergies`): along the reference gait, per-frame non-negative least
squares activations that reproduce the reference inverse-dynamics moments, and their
non-negative factorization into S synergy vectors.

Integration: classical Runge-Kutta, :data:`TIME_STEP` (s), commands held over each step.
Arrays: time on axis 0; SI units and radians.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import casadi as cs
import numpy as np
from scipy.interpolate import make_interp_spline
from scipy.optimize import nnls

from nmsm.examples.subject_model import MUSCLE_COORDINATES, STANDING_HEIGHT
from nmsm.examples.subject_motion import PRESCRIBED, prescribed_values
from nmsm.examples.subject_truth import MuscleTruth
from nmsm.model import hill
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.foot_contact import ContactSurfaceModel
from nmsm.model.muscle_geometry import MuscleGeometry

TIME_STEP = 0.0005
#: tracking feedback on hip flexion, knee, ankle (1/s^2, 1/s)
GAIN_POSITION = np.array([400.0, 400.0, 400.0])
GAIN_VELOCITY = np.array([40.0, 40.0, 40.0])
#: time constants (s) of the synergy commands rising and falling toward the controller's targets
RISE, FALL = 0.012, 0.040
#: largest muscle activation the controller asks for (headroom for the excitation)
MAX_ACTIVATION = 0.85


@attrs.frozen
class Reference:
    """The reference gait on a fine time grid: ``q``, ``u``, ``udot`` (T, n), model order."""

    time: np.ndarray
    q: np.ndarray
    u: np.ndarray
    udot: np.ndarray


def reference_from_samples(time: np.ndarray, q: np.ndarray, names: Sequence[str], fine_time: np.ndarray) -> Reference:
    """Quintic-spline the leg coordinates, exact values for the prescribed ones."""
    out_q = np.zeros((fine_time.size, len(names)))
    out_u, out_udot = np.zeros_like(out_q), np.zeros_like(out_q)
    for i, name in enumerate(names):
        if name in PRESCRIBED:
            out_q[:, i], out_u[:, i], out_udot[:, i] = prescribed_values(name, fine_time, STANDING_HEIGHT)
        else:
            spline = make_interp_spline(time, q[:, i], k=5)
            out_q[:, i], out_u[:, i], out_udot[:, i] = spline(fine_time), spline(fine_time, 1), spline(fine_time, 2)
    return Reference(fine_time, out_q, out_u, out_udot)


@attrs.frozen
class MuscleArrays:
    """Muscle properties as arrays (M,) in model muscle order."""

    f0: np.ndarray
    lo: np.ndarray
    lts: np.ndarray
    alpha: np.ndarray
    tau_a: np.ndarray
    nonlinearity: np.ndarray

    @classmethod
    def of(cls, truths: Sequence[MuscleTruth]) -> MuscleArrays:
        return cls(*(np.array([getattr(m, k) for m in truths]) for k in (
            "max_isometric_force", "optimal_fiber_length", "tendon_slack_length", "pennation",
            "activation_time_constant", "nonlinearity")))


class SubjectDynamics:
    """CasADi functions of the true subject (see module docstring)."""

    def __init__(self, model, muscles: MuscleArrays, contact: ContactSurfaceModel) -> None:
        self.model = model
        self.cm = CasadiModel(model)
        self.names = model.coordinate_names
        self.free = [self.names.index(c) for c in MUSCLE_COORDINATES]
        self.prescribed = [i for i in range(len(self.names)) if i not in self.free]
        self.muscled = [self.names.index(c) for c in MUSCLE_COORDINATES]
        self.muscles = muscles
        self.geometry = MuscleGeometry(model, list(model.muscle_names), list(MUSCLE_COORDINATES)).function()
        self.contact = contact
        self.loads = contact.body_loads_function(self.cm)
        self.grf = contact.ground_reactions_function(self.cm)
        self.inverse = self.cm.inverse_dynamics_function(contact.bodies)
        self.mass = self.cm.mass_matrix_function()

    def muscle_moments(self, q, u, a):
        """(3,) muscle moments on hip flexion, knee, ankle and the (M,) tendon forces."""
        m = self.muscles
        length, velocity, arms = self.geometry(q, u)
        lt = hill.normalized_fiber_length(length, cs.DM(m.lo), cs.DM(m.lts), cs.DM(m.alpha))
        vt = hill.normalized_fiber_velocity(velocity, cs.DM(m.lo), cs.DM(m.alpha))
        force = hill.tendon_force(a, lt, vt, cs.DM(m.f0), cs.DM(m.alpha))
        return cs.mtimes(arms.T, force), force, (length, velocity, arms, lt, vt)

    def accelerations(self, q, u, udot_prescribed, a):
        """Accelerations of the free coordinates (3,) and the contact loads (9 x 2)."""
        loads = self.loads(q, u)
        udot = cs.SX.zeros(len(self.names))
        for i in self.prescribed:
            udot[i] = udot_prescribed[i]
        bias = self.inverse(q, u, udot, loads)
        applied = cs.SX.zeros(len(self.names))
        moments, _, _ = self.muscle_moments(q, u, a)
        for k, i in enumerate(self.muscled):
            applied[i] = moments[k]
        mass = self.mass(q)
        free = self.free
        rhs = cs.vertcat(*[applied[i] - bias[i] for i in free])
        block = cs.vertcat(*[cs.horzcat(*[mass[i, j] for j in free]) for i in free])
        return cs.solve(block, rhs), loads


# ---------------------------------------------------------------------------------- design
@attrs.frozen
class Design:
    """The synergy vectors ``weights`` (S, M), largest weight 1, factored from the per-frame
    ``activations`` (T, M) on ``time`` (s) that give the reference ``moments`` (T, 3)."""

    time: np.ndarray
    weights: np.ndarray
    activations: np.ndarray
    moments: np.ndarray


def _nmf(data: np.ndarray, rank: int, seed: int = 0, iterations: int = 3000) -> tuple[np.ndarray, np.ndarray]:
    """Non-negative ``data (T, M) ~ C (T, S) W (S, M)`` (multiplicative updates, best of 10)."""
    rng = np.random.default_rng(seed)
    best = None
    for _ in range(10):
        c = rng.uniform(0.1, 1.0, (data.shape[0], rank))
        w = rng.uniform(0.1, 1.0, (rank, data.shape[1]))
        for _ in range(iterations):
            w *= (c.T @ data) / np.maximum(c.T @ c @ w, 1e-12)
            c *= (data @ w.T) / np.maximum(c @ w @ w.T, 1e-12)
        error = np.linalg.norm(data - c @ w)
        if best is None or error < best[0]:
            best = (error, c, w)
    _, c, w = best
    scale = w.max(axis=1)
    return c * scale[None, :], w / scale[:, None]


def design_synergies(dynamics: SubjectDynamics, reference: Reference, time: np.ndarray, n_synergies: int,
                     regularization: float = 1e-3) -> Design:
    """Synergy vectors of activations reproducing the reference moments (see module
    docstring); ``time`` (T,) the design frames (s), inside ``reference.time``."""
    index = np.searchsorted(reference.time, time)
    q, u, udot = reference.q[index], reference.u[index], reference.udot[index]
    n = len(time)
    loads = np.array(dynamics.loads.map(n)(q.T, u.T)).reshape(9, 2, n, order="F")
    tau = np.array(dynamics.inverse.map(n)(q.T, u.T, udot.T, loads.reshape(9, 2 * n, order="F"))).T
    m = dynamics.muscles
    length, velocity, arms = (np.array(v) for v in dynamics.geometry.map(n)(q.T, u.T))
    length, velocity = length.T, velocity.T  # (T, M)
    arms = arms.reshape(len(m.f0), 3, n, order="F").transpose(2, 1, 0)  # (T, 3, M)
    lt = hill.normalized_fiber_length(length, m.lo, m.lts, m.alpha)
    vt = hill.normalized_fiber_velocity(velocity, m.lo, m.alpha)
    active = hill.active_tendon_force(1.0, lt, vt, m.f0, m.alpha)  # (T, M) per unit activation
    passive = hill.passive_tendon_force(lt, m.f0, m.alpha)
    target = tau[:, dynamics.muscled] - np.einsum("tcm,tm->tc", arms, passive)
    scale = 1.0 / np.maximum(np.abs(target).max(axis=0), 1.0)
    activations = np.zeros_like(length)
    for k in range(n):
        gain = arms[k] * active[k][None, :] * scale[:, None]
        lhs = np.vstack([gain, np.sqrt(regularization) * np.eye(len(m.f0))])
        activations[k] = nnls(lhs, np.concatenate([target[k] * scale, np.zeros(len(m.f0))]))[0]
    _, weights = _nmf(activations + 1e-3, n_synergies)
    return Design(time, weights, activations, tau[:, dynamics.muscled])


# ---------------------------------------------------------------------------------- simulation
@attrs.frozen
class Simulation:
    """The recorded gait: on ``time`` (T,) s, ``q``, ``u``, ``udot`` (T, n) model order;
    synergy commands ``c`` (T, S), activations ``a = c W`` (T, M); contact ``loads``
    (T, 9, 2) on (hindfoot, toes); ground reaction ``force`` and ``moment`` (T, 3) about the
    ground origin; muscle ``moments`` (T, 3) on hip flexion, knee, ankle."""

    time: np.ndarray
    q: np.ndarray
    u: np.ndarray
    udot: np.ndarray
    c: np.ndarray
    a: np.ndarray
    loads: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    moments: np.ndarray


class _Functions:
    """Per-step CasADi functions of the simulation."""

    def __init__(self, dynamics: SubjectDynamics, weights: np.ndarray) -> None:
        names = len(dynamics.names)
        self.dynamics = dynamics
        n_syn = weights.shape[0]
        k = len(dynamics.prescribed)
        x = cs.SX.sym("x", 6)  # q_free, u_free
        w = cs.SX.sym("w", 3 * k)  # prescribed q, u, udot
        c = cs.SX.sym("c", n_syn)
        q, u, udot_p = cs.SX.zeros(names), cs.SX.zeros(names), cs.SX.zeros(names)
        for j, i in enumerate(dynamics.free):
            q[i], u[i] = x[j], x[3 + j]
        for j, i in enumerate(dynamics.prescribed):
            q[i], u[i], udot_p[i] = w[j], w[k + j], w[2 * k + j]
        a = cs.mtimes(cs.DM(weights.T), c)
        udot_free, loads = dynamics.accelerations(q, u, udot_p, a)
        moments = dynamics.muscle_moments(q, u, a)[0]
        self.rhs = cs.Function("rhs", [x, w, c], [cs.vertcat(x[3:6], udot_free)])
        self.outputs = cs.Function("outputs", [x, w, c], [udot_free, cs.vec(loads), moments])
        # control: muscle moments = J c + passive; required moments of a desired acceleration
        m = dynamics.muscles
        length, velocity, arms = dynamics.geometry(q, u)
        lt = hill.normalized_fiber_length(length, cs.DM(m.lo), cs.DM(m.lts), cs.DM(m.alpha))
        vt = hill.normalized_fiber_velocity(velocity, cs.DM(m.lo), cs.DM(m.alpha))
        active = hill.active_tendon_force(1.0, lt, vt, cs.DM(m.f0), cs.DM(m.alpha))
        passive = hill.passive_tendon_force(lt, cs.DM(m.f0), cs.DM(m.alpha))
        jac = cs.mtimes(arms.T, cs.mtimes(cs.diag(active), cs.DM(weights.T)))
        desired = cs.SX.sym("udot_desired", 3)
        udot = cs.SX(udot_p)
        for j, i in enumerate(dynamics.free):
            udot[i] = desired[j]
        tau = dynamics.inverse(q, u, udot, dynamics.loads(q, u))
        needed = cs.vertcat(*[tau[i] for i in dynamics.muscled]) - cs.mtimes(arms.T, passive)
        self.control = cs.Function("control", [x, w, desired], [jac, needed])


def simulate(dynamics: SubjectDynamics, reference: Reference, weights: np.ndarray, t0: float, t1: float,
             time_step: float = TIME_STEP) -> Simulation:
    """Integrate from the reference state at ``t0`` to ``t1`` (s) (see module docstring).

    Each step: desired accelerations ``udot_ref + K (q_ref - q) + D (u_ref - u)``; the
    commands ``v`` in [0, 1] whose muscle moments best produce them (bounded least squares),
    scaled down when a muscle's activation ``v W`` would exceed :data:`MAX_ACTIVATION`;
    the command state ``c`` follows ``v`` with :data:`RISE` / :data:`FALL` time constants
    (so activations never rise or fall faster than the muscles' dynamics allow); RK4 over
    the step with ``c`` held.
    """
    from scipy.optimize import lsq_linear

    f = _Functions(dynamics, weights)
    free, prescribed = dynamics.free, dynamics.prescribed
    steps = int(round((t1 - t0) / time_step))
    time = t0 + time_step * np.arange(steps + 1)
    half = t0 + time_step * (np.arange(steps) + 0.5)
    w_full, ref_full = _inputs(reference, dynamics, time)
    w_half, _ = _inputs(reference, dynamics, half)
    n_syn = weights.shape[0]
    x = np.concatenate([ref_full[0][:, 0], ref_full[1][:, 0]])
    c = np.zeros(n_syn)
    states, commands = [x.copy()], []
    regularization = np.sqrt(1e-4) * np.eye(n_syn)
    h = time_step
    for k in range(steps + 1):
        q_ref, u_ref, udot_ref = (r[:, k] for r in ref_full)
        error_q, error_u = q_ref - x[:3], u_ref - x[3:]
        desired = udot_ref + GAIN_POSITION * error_q + GAIN_VELOCITY * error_u
        jac, needed = (np.array(v) for v in f.control(x, w_full[:, k], desired))
        scale = 1.0 / np.array([100.0, 100.0, 100.0])
        target = lsq_linear(np.vstack([jac * scale[:, None], regularization]),
                            np.concatenate([needed.ravel() * scale, np.zeros(n_syn)]), bounds=(0.0, 1.0)).x
        target /= max(1.0, float(np.max(weights.T @ target)) / MAX_ACTIVATION)
        rate = np.where(target > c, 1.0 / RISE, 1.0 / FALL)
        c = c + (target - c) * (1.0 - np.exp(-rate * h)) if k > 0 else target.copy()
        commands.append(c.copy())
        if k == steps:
            break
        k1 = np.array(f.rhs(x, w_full[:, k], c)).ravel()
        k2 = np.array(f.rhs(x + h / 2 * k1, w_half[:, k], c)).ravel()
        k3 = np.array(f.rhs(x + h / 2 * k2, w_half[:, k], c)).ravel()
        k4 = np.array(f.rhs(x + h * k3, w_full[:, k + 1], c)).ravel()
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        states.append(x.copy())
    states_arr, commands_arr = np.array(states), np.array(commands)
    n = time.size
    udot_free, loads, moments = (np.array(v) for v in f.outputs.map(n)(states_arr.T, w_full, commands_arr.T))
    names = len(dynamics.names)
    kp = len(prescribed)
    q_all, u_all, udot_all = np.zeros((n, names)), np.zeros((n, names)), np.zeros((n, names))
    q_all[:, prescribed], u_all[:, prescribed], udot_all[:, prescribed] = (w_full[:kp].T, w_full[kp:2 * kp].T,
                                                                         w_full[2 * kp:].T)
    q_all[:, free], u_all[:, free], udot_all[:, free] = states_arr[:, :3], states_arr[:, 3:], udot_free.T
    loads = loads.T.reshape(n, 9, 2, order="F")
    force = loads[:, 0:3, :].sum(axis=2)
    moment = np.zeros_like(force)
    for b in range(2):
        moment += np.cross(loads[:, 3:6, b], loads[:, 0:3, b]) + loads[:, 6:9, b]
    return Simulation(time, q_all, u_all, udot_all, commands_arr, commands_arr @ weights, loads, force, moment,
                      moments.T)


def _inputs(reference: Reference, dynamics: SubjectDynamics, t: np.ndarray
            ) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Prescribed ``(q, u, udot)`` stacked (3k, len(t)) and the free coordinates' reference
    ``(q, u, udot)`` (3, len(t)) each, at times ``t``."""
    q = np.empty((t.size, len(dynamics.names)))
    u, udot = np.empty_like(q), np.empty_like(q)
    for i, name in enumerate(dynamics.names):
        if name in PRESCRIBED:
            q[:, i], u[:, i], udot[:, i] = prescribed_values(name, t, STANDING_HEIGHT)
        else:  # simulated coordinates and the toes: the reference
            q[:, i] = np.interp(t, reference.time, reference.q[:, i])
            u[:, i] = np.interp(t, reference.time, reference.u[:, i])
            udot[:, i] = np.interp(t, reference.time, reference.udot[:, i])
    p, f = dynamics.prescribed, dynamics.free
    return np.vstack([q[:, p].T, u[:, p].T, udot[:, p].T]), (q[:, f].T, u[:, f].T, udot[:, f].T)

"""Hill-type muscle model with a rigid tendon (NMSM Pipeline, Meyer et al. 2017).

Shared by Muscle-Tendon Personalization (MTP), Muscle-Tendon Length Initialization (MTLI),
Neural Control Personalization (NCP) and Treatment Optimization (TO/VO/DO). Every function
is elementwise or vectorized and accepts either numpy arrays (any shape, broadcasting as
numpy does) or CasADi ``SX``/``MX``/``DM`` expressions (2-D; broadcasting a scalar or a
matching shape). No function imports OpenSim.

Model (tendon rigid, no fiber dynamics, ``alpha`` = pennation at optimal fiber length):

* normalized fiber length   ``l = (L_MT - l_ts) / (l_o cos alpha)``                 [-]
* normalized fiber velocity ``v = V_MT / (vmax_factor * l_o * cos alpha)``          [-]
  (``vmax_factor`` in optimal fiber lengths per second, 10 by default)
* active force-length  ``f_L(l) = sum_i b1i exp(-0.5 (l - b2i)^2 / (b3i + b4i l)^2)``
* force-velocity       ``f_V(v) = d1 + d2 atan(d3 + d4 atan(d5 + d6 v))``
* passive force-length ``f_P(l) = e1 softplus(e2 (l - e3))`` (stable softplus)
* tendon force         ``F = F0 (a f_L f_V + f_P) cos alpha``                       [N]
* joint moment         ``M_j = sum_m r_jm F_m``                                     [N m]

The curves' constants are a :class:`MuscleCurves`: :data:`CURVES` (the pipeline's since
2024, OpenSim's ``DeGrooteFregly2016Muscle``) by default; :data:`CURVES_2023` holds the
earlier f_L and f_V constants the original's 2023 unit-test data were computed with.

Activation (Meyer 2017 eqs 5-8):

* excitation ``e(t) = s_emg * EMG(t - delay)`` (see :mod:`nmsm.tools.mtp.emg_spline`)
* neural activation by the implicit second-order backward difference of
  ``dn/dt = (c1 e + c2)(e - n)`` with ``c1 = 1/tau_a - 1/tau_d``, ``c2 = 1/tau_d``,
  ``tau_d = 4 tau_a``: ``n_k = (2 dt (c1 e_k + c2) e_k + 4 n_{k-1} - n_{k-2}) /
  (2 dt (c1 e_k + c2) + 3)``, ``n_0 = n_1 = 0``;
* activation nonlinearity ``a = (1 - A) n + A (g4 / (g1 (n + g6)^g5 + g2) + g3)``.

How NCP / TO compute muscle forces and moments::

    l = normalized_fiber_length(L_MT, l_o, l_ts, alpha)
    v = normalized_fiber_velocity(V_MT, l_o, alpha, vmax_factor)
    F = tendon_force(a, l, v, F0, alpha)            # (frames, muscles)
    M = joint_moments(moment_arms, F)               # moment_arms (frames, coords, muscles)
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

#: active force-length coefficients b1 (peak), b2 (centre), b3, b4 (width = b3 + b4 l)
ACTIVE_FORCE_LENGTH_B = (
    (0.8174335195120225, 0.43130780147182907, 0.1),
    (1.054348561163096, 0.7163004817144202, 1.0),
    (0.16194288662761705, -0.029060905806803296, 0.353553390593274),
    (0.06381565266097716, 0.19835014521987723, 0.0),
)
#: force-velocity coefficients d1..d6
FORCE_VELOCITY_D = (
    -32.51401019139919,
    22.160392466960214,
    18.7932134796918,
    6.320952269683997,
    -0.27671677680513945,
    8.053304562566995,
)
#: passive force-length coefficients e1..e3
PASSIVE_FORCE_LENGTH_E = (0.232000797810576, 12.438535493526128, 1.329470475731338)


@attrs.frozen
class MuscleCurves:
    """Constants of the three normalized curves (module docstring: formulas).

    ``active_force_length``: rows b1 (peaks), b2 (centres), b3, b4 (width ``b3 + b4 l``) of
    the three Gaussians; ``force_velocity``: d1..d6; ``passive_force_length``: e1..e3.
    """

    active_force_length: tuple[tuple[float, float, float], ...]
    force_velocity: tuple[float, float, float, float, float, float]
    passive_force_length: tuple[float, float, float]


#: the curves of the NMSM Pipeline since 2024 (OpenSim's DeGrooteFregly2016Muscle)
CURVES = MuscleCurves(ACTIVE_FORCE_LENGTH_B, FORCE_VELOCITY_D, PASSIVE_FORCE_LENGTH_E)
#: the curves of the original's early-2023 code, with which its 2023 MTP and NCP unit-test
#: data (``mtp/cost_function_unit_2023``, ``ncp/cost_function_unit_2023``) were computed:
#: f_L with De Groote et al. 2016's (supplement) constants, an earlier f_V fit (f_V(0) =
#: 1.0005; nmsm-core commit a1fc3dca), the same f_P. They reproduce those data's model
#: moments to 2e-15 of the peak (the current curves: 6.2e-4).
CURVES_2023 = MuscleCurves(
    (
        (0.814483478343008, 0.433004984392647, 0.1),
        (1.055033428970575, 0.716775413397760, 1.0),
        (0.162384573599574, -0.029947116970696, 0.353553390593274),
        (0.063303448465465, 0.200356847296188, 0.0),
    ),
    (-12.4090551101489, 9.35818070443882, 7.93116233095206, 2.70637350085154, -0.274108493130008,
     8.03512618783281),
    PASSIVE_FORCE_LENGTH_E,
)
#: activation nonlinearity coefficients g1..g6 (Meyer 2017 eq 8, relabelled)
ACTIVATION_NONLINEARITY_G = (
    29.280183270562596,
    4.107869238218326,
    1.000004740962477,
    -7.623282868703527,
    17.227022969058535,
    0.884220539986325,
)
#: floor of the squared active force-length widths (see :func:`active_force_length`)
ACTIVE_WIDTH_FLOOR = 1e-20
#: deactivation time constant / activation time constant
DEACTIVATION_RATIO = 4.0
#: unit of the ``.osimx``'s ``activation_time_constant`` (MTP's raw design variable), s
OSIMX_TIME_CONSTANT_UNIT = 0.01


def time_constants_from_osimx(value: float) -> tuple[float, float]:
    """``(τ_a, τ_d)`` in s of an ``.osimx`` ``activation_time_constant`` (units of 0.01 s):
    ``τ_a = 0.01 value``, ``τ_d = 4 τ_a`` (the NMSM Pipeline's activation dynamics, docs/model.md)."""
    tau = OSIMX_TIME_CONSTANT_UNIT * float(value)
    return tau, DEACTIVATION_RATIO * tau
#: default maximum shortening velocity, optimal fiber lengths per second
DEFAULT_VMAX_FACTOR = 10.0
#: default maximum muscle stress sigma0 (Pa) relating F0 to muscle volume
DEFAULT_MAXIMUM_MUSCLE_STRESS = 610_000.0


def _is_casadi(*values: Any) -> bool:
    for v in values:
        mod = type(v).__module__
        if mod.startswith("casadi"):
            return True
    return False


def _ops(*values: Any) -> Any:
    """The math namespace (numpy or casadi) fitting the arguments."""
    if _is_casadi(*values):
        import casadi as cs

        return cs
    return np


def softplus(x: Any) -> Any:
    """``log(1 + exp(x))`` evaluated without overflow (numpy or CasADi)."""
    if _is_casadi(x):
        import casadi as cs

        return cs.fmax(x, 0) + cs.log1p(cs.exp(-cs.fabs(x)))
    return np.logaddexp(0.0, np.asarray(x, dtype=float))


# ----- force-length-velocity curves -------------------------------------------------------
def active_force_length(normalized_length: Any, curves: MuscleCurves = CURVES) -> Any:
    """Normalized active fiber force ``f_L`` (-) at normalized fiber length (-)."""
    l = normalized_length
    casadi = _is_casadi(l)
    ops = _ops(l)
    if not casadi:
        l = np.asarray(l, dtype=float)
    b1, b2, b3, b4 = curves.active_force_length
    total = 0
    for i in range(3):
        width = b3[i] + b4[i] * l
        squared = width**2
        if b4[i] != 0.0:
            # the second Gaussian's width vanishes at l = 0.1465; a floor keeps the value
            # (0 there) and its derivatives finite, and changes nothing for |width| > 1e-10
            squared = ops.fmax(squared, ACTIVE_WIDTH_FLOOR) if casadi else np.maximum(squared, ACTIVE_WIDTH_FLOOR)
        total = total + b1[i] * ops.exp(-0.5 * (l - b2[i]) ** 2 / squared)
    return total


def force_velocity(normalized_velocity: Any, curves: MuscleCurves = CURVES) -> Any:
    """Normalized force-velocity factor ``f_V`` (-) at normalized fiber velocity (-)."""
    ops = _ops(normalized_velocity)
    d1, d2, d3, d4, d5, d6 = curves.force_velocity
    return d1 + d2 * ops.arctan(d3 + d4 * ops.arctan(d5 + d6 * normalized_velocity))


def passive_force_length(normalized_length: Any, curves: MuscleCurves = CURVES) -> Any:
    """Normalized passive fiber force ``f_P`` (-): ``e1 softplus(e2 (l - e3))``."""
    e1, e2, e3 = curves.passive_force_length
    return e1 * softplus(e2 * (normalized_length - e3))


# ----- kinematics ---------------------------------------------------------------------------
def normalized_fiber_length(
    muscle_tendon_length: Any, optimal_fiber_length: Any, tendon_slack_length: Any, pennation_angle: Any
) -> Any:
    """``(L_MT - l_ts) / (l_o cos alpha)`` (-). Lengths in m, angle in rad; broadcast."""
    ops = _ops(muscle_tendon_length, optimal_fiber_length, tendon_slack_length, pennation_angle)
    return (muscle_tendon_length - tendon_slack_length) / (optimal_fiber_length * ops.cos(pennation_angle))


def normalized_fiber_velocity(
    muscle_tendon_velocity: Any,
    optimal_fiber_length: Any,
    pennation_angle: Any,
    vmax_factor: Any = DEFAULT_VMAX_FACTOR,
) -> Any:
    """``V_MT / (vmax_factor l_o cos alpha)`` (-). Velocity in m/s, ``vmax_factor`` in l_o/s."""
    ops = _ops(muscle_tendon_velocity, optimal_fiber_length, pennation_angle, vmax_factor)
    return muscle_tendon_velocity / (vmax_factor * optimal_fiber_length * ops.cos(pennation_angle))


# ----- forces and moments -------------------------------------------------------------------
def passive_tendon_force(normalized_length: Any, max_isometric_force: Any, pennation_angle: Any,
                         curves: MuscleCurves = CURVES) -> Any:
    """Passive force along the tendon ``F0 f_P(l) cos alpha`` (N)."""
    ops = _ops(normalized_length, max_isometric_force, pennation_angle)
    return max_isometric_force * passive_force_length(normalized_length, curves) * ops.cos(pennation_angle)


def active_tendon_force(
    activation: Any, normalized_length: Any, normalized_velocity: Any, max_isometric_force: Any, pennation_angle: Any,
    curves: MuscleCurves = CURVES,
) -> Any:
    """Active force along the tendon ``F0 a f_L(l) f_V(v) cos alpha`` (N)."""
    ops = _ops(activation, normalized_length, normalized_velocity, max_isometric_force, pennation_angle)
    return (
        max_isometric_force
        * activation
        * active_force_length(normalized_length, curves)
        * force_velocity(normalized_velocity, curves)
        * ops.cos(pennation_angle)
    )


def tendon_force(
    activation: Any, normalized_length: Any, normalized_velocity: Any, max_isometric_force: Any, pennation_angle: Any,
    curves: MuscleCurves = CURVES,
) -> Any:
    """Total muscle-tendon force ``F0 (a f_L f_V + f_P) cos alpha`` (N)."""
    ops = _ops(activation, normalized_length, normalized_velocity, max_isometric_force, pennation_angle)
    return (
        max_isometric_force
        * (
            activation * active_force_length(normalized_length, curves) * force_velocity(normalized_velocity, curves)
            + passive_force_length(normalized_length, curves)
        )
        * ops.cos(pennation_angle)
    )


def joint_moments(moment_arms: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """Joint moments (N m) from moment arms (m) and tendon forces (N), numpy only.

    ``moment_arms`` shape ``(..., n_coordinates, n_muscles)``, ``forces`` shape
    ``(..., n_muscles)`` (leading axes broadcast, e.g. trials x frames);
    returns ``(..., n_coordinates)``. For CasADi, build ``R @ F`` per frame.
    """
    return np.einsum("...cm,...m->...c", np.asarray(moment_arms, float), np.asarray(forces, float))


def max_isometric_force_from_volume(muscle_volume: Any, optimal_fiber_length: Any, maximum_muscle_stress: Any) -> Any:
    """``F0 = V / l_o * sigma`` (N): volume (m^3), optimal fiber length (m), stress (Pa)."""
    return muscle_volume / optimal_fiber_length * maximum_muscle_stress


def muscle_volume(max_isometric_force: Any, optimal_fiber_length: Any, maximum_muscle_stress: Any) -> Any:
    """``V = F0 l_o / sigma`` (m^3): the inverse of :func:`max_isometric_force_from_volume`."""
    return max_isometric_force * optimal_fiber_length / maximum_muscle_stress


# ----- activation ---------------------------------------------------------------------------
def clip_negative(x: Any, smoothing: float = 0.0) -> Any:
    """``max(x, 0)``; with ``smoothing`` = s > 0 a twice continuously differentiable ramp.

    The smooth ramp equals ``max(x, 0)`` outside ``|x| < s``; inside it is
    ``s g(x/s)`` with ``g(t) = t/2 + 3/16 + 3t^2/8 - t^4/16`` (value, slope and curvature
    match at ``t = +-1``). It exceeds ``max(x, 0)`` by at most ``3 s / 16`` (at 0) and its
    curvature is at most ``3 / (4 s)``, so gradient-based solvers neither stall on the kink
    nor face a near-kink (MTP with synergy extrapolation).
    """
    ops = _ops(x)
    if smoothing <= 0:
        return ops.fmax(x, 0) if ops is not np else np.maximum(x, 0.0)
    s = float(smoothing)
    t = x / s
    ramp = s * (0.5 * t + 3.0 / 16.0 + 0.375 * t * t - t**4 / 16.0)
    if ops is np:
        return np.where(np.abs(t) < 1.0, ramp, np.maximum(x, 0.0))
    return ops.if_else(ops.fabs(t) < 1.0, ramp, ops.fmax(x, 0))


def activation_nonlinearity(neural_activation: Any, nonlinearity: Any) -> Any:
    """Muscle activation from neural activation with nonlinearity constant ``A`` in [0, 0.35]."""
    g1, g2, g3, g4, g5, g6 = ACTIVATION_NONLINEARITY_G
    n = neural_activation
    if _is_casadi(n, nonlinearity):
        import casadi as cs

        curved = g4 / (g1 * cs.power(n + g6, g5) + g2) + g3
    else:
        n = np.asarray(n, dtype=float)
        curved = g4 / (g1 * np.power(n + g6, g5) + g2) + g3
    return (1 - nonlinearity) * n + nonlinearity * curved


def neural_activation(excitation: np.ndarray, activation_time_constant: Any, time_step: Any) -> np.ndarray:
    """Neural activation by the implicit BDF2 scheme (numpy), ``n_0 = n_1 = 0``.

    ``excitation``: shape ``(..., n_frames)`` (time on the **last** axis);
    ``activation_time_constant`` (s) and ``time_step`` (s) broadcast against
    ``excitation[..., 0]``. Returns the same shape as ``excitation``. Padding frames are
    not removed here; negative values are kept (callers clip after dropping padding).
    """
    e = np.asarray(excitation, dtype=float)
    tau_a = np.asarray(activation_time_constant, dtype=float)
    dt = np.asarray(time_step, dtype=float)
    c2 = 1.0 / (DEACTIVATION_RATIO * tau_a)
    c1 = 1.0 / tau_a - c2
    n = np.zeros_like(e)
    for k in range(2, e.shape[-1]):
        ek = e[..., k]
        gain = 2.0 * dt * (c1 * ek + c2)
        n[..., k] = (gain * ek + 4.0 * n[..., k - 1] - n[..., k - 2]) / (gain + 3.0)
    return n


def neural_activation_function(n_frames: int, name: str = "neural_activation") -> Any:
    """CasADi ``Function(e[n_frames], tau_a, dt) -> n[n_frames]`` (SX, BDF2, ``n_0 = n_1 = 0``).

    ``tau_a`` activation time constant (s), ``dt`` time step (s). Map it over muscles and
    trials (``f.map(n)``) inside MX problems.
    """
    import casadi as cs

    e = cs.SX.sym("e", n_frames)
    tau = cs.SX.sym("tau_a")
    dt = cs.SX.sym("dt")
    c2 = 1.0 / (DEACTIVATION_RATIO * tau)
    c1 = 1.0 / tau - c2
    n: list[Any] = [cs.SX(0), cs.SX(0)][: min(2, n_frames)]
    for k in range(2, n_frames):
        gain = 2.0 * dt * (c1 * e[k] + c2)
        n.append((gain * e[k] + 4.0 * n[k - 1] - n[k - 2]) / (gain + 3.0))
    return cs.Function(name, [e, tau, dt], [cs.vertcat(*n)], ["e", "tau_a", "dt"], ["n"])

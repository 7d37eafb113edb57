"""Smoothed Bhargava (2004) metabolic model of Design Optimization (docs/treatment.md).

Per muscle (activation ``a``, normalized fiber length ``l̃`` and velocity ``ṽ`` of the
rigid-tendon Hill model, :mod:`nmsm.model.hill`; ``F0`` N, ``l_o`` m, pennation ``α`` rad,
``vmax`` optimal fiber lengths per second), with σ = 610 kPa, ρ = 1059.7 kg/m³, 50 % fast
twitch fibers and smoothing ``b = 10``::

    m    = ρ F0 l_o / σ                                   muscle mass (kg)
    f_a  = 0.5 (1 - cos(π a / 2)),  s_a = 0.5 sin(π a / 2)
    F_CE = F0 a f_L(l̃) f_V(ṽ),  F_iso = F0 a f_L(l̃) f_V(0),  F_tot = F_CE + F0 f_P(l̃)
    A    = m (133 f_a + 40 s_a)                           activation heat (W)
    Mh   = m g(l̃) (111 f_a + 74 s_a)                      maintenance heat (W),
           g = 0.5 (l̃ <= 0.5), l̃ (<= 1), 3 - 2 l̃ (<= 1.5), 0 beyond
    v    = ṽ vmax l_o cos α                               fiber velocity (m/s, > 0 lengthening)
    p    = 0.5 + 0.5 tanh(b v)                            smooth "lengthening" switch
    S    = -[(1 - p)(0.16 F_iso + 0.18 F_tot) + p 0.157 F_tot] v     shortening heat (W)
    W    = -F_CE v (1 - p)                                positive mechanical work rate (W)
    S   -= T (0.5 + 0.5 tanh(-b T)),  T = A + Mh + S + W  (a negative total is removed from S)
    heat = m h(H / m),  H = A + Mh + S,  h(x) = x + (1 - x)(0.5 + 0.5 tanh(b (1 - x)))
           (heat per muscle mass smoothly floored at 1 W/kg)
    rate = heat + W

and the whole body ``Ė = Σ rate + 1.2 W/kg × body mass`` (basal rate). ``(F0 f_V(ṽ)/f_V(0)``
is written as ``F_iso`` directly: the same value without dividing by ``f_V``.)
"""

from __future__ import annotations

import casadi as cs

from nmsm.model import hill

MAXIMUM_MUSCLE_STRESS = 610_000.0  # Pa
MUSCLE_DENSITY = 1059.7  # kg/m³
FAST_TWITCH_RATIO = 0.5
SMOOTHING = 10.0
BASAL_RATE = 1.2  # W/kg


def _step(x: cs.SX) -> cs.SX:
    """Smooth step 0 -> 1 around 0 (``0.5 + 0.5 tanh(b x)``)."""
    return 0.5 + 0.5 * cs.tanh(SMOOTHING * x)


def length_factor(l_norm: cs.SX) -> cs.SX:
    """Bhargava's maintenance-heat length dependence g(l̃) (piecewise linear, continuous)."""
    return cs.if_else(l_norm <= 0.5, 0.5,
                      cs.if_else(l_norm <= 1.0, l_norm, cs.if_else(l_norm <= 1.5, 3.0 - 2.0 * l_norm, 0.0)))


def muscle_rates(a: cs.SX, l_norm: cs.SX, v_norm: cs.SX, F0: cs.SX, lo: cs.SX, cos_alpha: cs.SX,
                 vmax: cs.SX) -> cs.SX:
    """Metabolic rate (W) of each muscle (elementwise over equal-shaped SX columns)."""
    mass = MUSCLE_DENSITY * F0 * lo / MAXIMUM_MUSCLE_STRESS
    angle = cs.pi / 2 * a
    fast = FAST_TWITCH_RATIO * (1 - cs.cos(angle))
    slow = (1 - FAST_TWITCH_RATIO) * cs.sin(angle)
    f_l = hill.active_force_length(l_norm)
    f_ce = F0 * a * f_l * hill.force_velocity(v_norm)
    f_iso = F0 * a * f_l * float(hill.force_velocity(0.0))
    f_tot = f_ce + F0 * hill.passive_force_length(l_norm)
    activation = mass * (133.0 * fast + 40.0 * slow)
    maintenance = mass * length_factor(l_norm) * (111.0 * fast + 74.0 * slow)
    velocity = v_norm * vmax * lo * cos_alpha
    p = _step(velocity)
    coefficient = (1 - p) * (0.16 * f_iso + 0.18 * f_tot) + p * 0.157 * f_tot
    shortening = -coefficient * velocity
    work = -f_ce * velocity * (1 - p)
    total = activation + maintenance + shortening + work
    shortening = shortening - total * _step(-total)
    per_mass = (activation + maintenance + shortening) / mass
    floored = per_mass + (1 - per_mass) * _step(1 - per_mass)
    return mass * floored + work


def metabolic_point_function(n_muscles: int) -> cs.Function:
    """SX ``(a, l̃, ṽ, p) -> Σ rate`` (W, muscles only) of one point; ``p`` (4 M,) =
    [F0..., l_o..., cos α..., vmax...]."""
    M = n_muscles
    a, ln, vn = (cs.SX.sym(s, M) for s in ("a", "l_norm", "v_norm"))
    p = cs.SX.sym("p", 4 * M)
    rates = muscle_rates(a, ln, vn, p[:M], p[M:2 * M], p[2 * M:3 * M], p[3 * M:])
    return cs.Function("bhargava", [a, ln, vn, p], [cs.sum1(rates)], ["a", "l_norm", "v_norm", "p"], ["rate"])

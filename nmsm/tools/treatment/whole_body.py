"""Whole-body quantities of a treatment model: centre of mass and central angular momentum.

``whole_body_function(model)`` is an SX function of one point
``(q (nq,), q̇ (nq,)) -> (c (3,), ċ (3,), H (3,))``, all in ground:

* ``c = Σ m_i c_i / M``                                   centre of mass (m)
* ``ċ = Σ m_i v_i / M``                                   its velocity (m/s)
* ``H = Σ [m_i (c_i - c) × (v_i - ċ) + R_i I_i R_iᵀ ω_i]``  angular momentum about the
  centre of mass (kg·m²/s), ``I_i`` the body's inertia about its own centre of mass

Models: nmsm's OpenSim adapter (``model.casadi``: the tree kinematics with OpenSim generalized
speeds), or any :class:`~nmsm.core.ocp_model.TreatmentModel` that also has
``mass_properties(body) -> (mass kg, centre of mass (3,) m in the body frame, inertia (3, 3)
kg·m² about it in body axes)``; for those, ``q̇`` must be the coordinate rates (velocities
are ``∂/∂q · q̇`` of the body poses).
"""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np

from nmsm.core.function_names import function_name


def _has_tree(model: Any) -> bool:
    return getattr(model, "casadi", None) is not None and hasattr(model.casadi, "kinematics")


def supports_whole_body(model: Any) -> bool:
    """True when :func:`whole_body_function` can be built for ``model``."""
    return _has_tree(model) or hasattr(model, "mass_properties")


def total_mass(model: Any) -> float:
    """Sum of the bodies' masses (kg)."""
    if _has_tree(model):
        return float(sum(b.mass for b in model.casadi.model.bodies.values()))
    return float(sum(model.mass_properties(b)[0] for b in model.body_names))


def _body_terms(model: Any, q: cs.SX, qd: cs.SX) -> list[tuple[Any, cs.SX, cs.SX, cs.SX, cs.SX]]:
    """Per body: (mass, centre of mass, its velocity, inertia in ground, angular velocity)."""
    out = []
    if _has_tree(model):
        kin = model.casadi.kinematics
        states = kin.forward(q, qd)
        for name in model.casadi.model.bodies:
            mass, com, inertia = kin.body_mass_properties(name)
            st = states[name]
            r = cs.mtimes(st.R, com)
            out.append((mass, st.p + r, st.v + cs.cross(st.w, r), cs.mtimes(cs.mtimes(st.R, inertia), st.R.T), st.w))
        return out
    for name in model.body_names:
        mass, com, inertia = model.mass_properties(name)
        R = model.body_rotation_function(name)(q)
        p = model.body_origin_function(name)(q)
        c = p + cs.mtimes(R, cs.DM(np.asarray(com, float)))
        v = cs.jtimes(c, q, qd)
        R_dot = cs.reshape(cs.jtimes(cs.vec(R), q, qd), 3, 3)
        W = cs.mtimes(R_dot, R.T)  # skew(ω)
        w = cs.vertcat(W[2, 1], W[0, 2], W[1, 0])
        I_g = cs.mtimes(cs.mtimes(R, cs.DM(np.asarray(inertia, float))), R.T)
        out.append((mass, c, v, I_g, w))
    return out


def whole_body_function(model: Any) -> cs.Function:
    """SX ``(q, qd[, p]) -> (com, com_velocity, angular_momentum)`` (see module docstring);
    ``p``: the model parameters of a parametric ``.osim`` adapter."""
    if not supports_whole_body(model):
        raise TypeError(f"{type(model).__name__} has no mass properties (needs an OpenSim model or "
                        "mass_properties(body))")
    nq = len(model.coordinate_names)
    q, qd = cs.SX.sym("q", nq), cs.SX.sym("qd", nq)
    bodies = _body_terms(model, q, qd)
    M = sum(float(b[0]) for b in bodies)
    if M <= 0:
        raise ValueError("the model's bodies have no mass")
    com = sum((b[0] * b[1] for b in bodies), cs.SX.zeros(3, 1)) / M
    vcom = sum((b[0] * b[2] for b in bodies), cs.SX.zeros(3, 1)) / M
    H = cs.SX.zeros(3, 1)
    for mass, c, v, I_g, w in bodies:
        H = H + mass * cs.cross(c - com, v - vcom) + cs.mtimes(I_g, w)
    parameters = [model.casadi.p] if _has_tree(model) and model.casadi.has_parameters else []
    return cs.Function("whole_body", [q, qd, *parameters], [com, vcom, H], ["q", "qd", *(["p"] if parameters else [])],
                       ["com", "com_velocity", "angular_momentum"])


def foot_reaction_function(contact_function: cs.Function, name: str = "foot", *,
                           moment_about_floor_point: bool = False) -> cs.Function:
    """SX ``(q, qd, p) -> (force (3,) N, moment about the ground origin (3,) N·m, reference
    point on the floor (3,) m)`` of a contact model's point function
    (:meth:`~nmsm.core.plugin_bases.ContactModel.point_function`); the point is its reported
    point with y = 0. The moment is summed from the loads it applies to its bodies,
    ``Σ r_b × f_b + t_b``, or, with ``moment_about_floor_point`` (GCP's elastic foundation,
    whose reported moment is about that floor point with the springs' forces on the floor, as
    its parameters were fitted), moved from the reported moment: ``M + P × F``."""
    q = cs.SX.sym("q", contact_function.size1_in(0))
    qd = cs.SX.sym("qd", contact_function.size1_in(1))
    p = cs.SX.sym("p", contact_function.size1_in(2))
    loads, total, moment, ref = contact_function(q, qd, p)
    floor_point = cs.vertcat(ref[0], 0, ref[2])
    if moment_about_floor_point:
        about_origin = moment + cs.cross(floor_point, total)
    else:
        about_origin = cs.SX.zeros(3, 1)
        for k in range(loads.shape[1]):
            about_origin += cs.cross(loads[3:6, k], loads[0:3, k]) + loads[6:9, k]
    return cs.Function(function_name("foot_reaction", name), [q, qd, p], [total, about_origin, floor_point])

"""Elastic-foundation foot-ground contact of Ground Contact Personalization, in CasADi.

A contact surface is a set of springs fixed to the hindfoot and toes bodies. Given the
springs' positions and velocities in ground (``(3, n)``, m and m/s; ground y is up), each
spring ``j`` with stiffness ``K_j`` (N/m) pushes on its body with (docs/gcp.md):

* vertical force (N), with ``y = 0.7 tanh((h - L0)/0.7)`` the smoothly clamped height
  above the resting spring length ``L0`` (m) and ``lc(x) = log(cosh(x))``::

      v = (K + k_low)/(K - k_low),  s = (K - k_low)/2
      F_el = -s (v y - c lc((y + h_off)/c)) + s (v y_max - c lc((y_max + h_off)/c))
      F_y  = F_el (1 - D ydot)

  ``k_low = 0.1`` N/m, ``h_off = 1e-3`` m, ``c = 1e-3`` m, ``y_max = 1e-2`` m: ``F_el`` is
  ``-K (y + h_off)`` in contact (``y`` a few ``c`` below ``-h_off``), has slope ``k_low``
  out of contact and is zero at ``y = y_max``.
  ``D`` (s/m) is the damping factor common to all springs.
* friction (N): with slip velocity ``u = (xdot + belt_speed, zdot)`` (m/s),
  ``v_s = |u|`` (0 below 1e-10), ``|F_h| = F_y (mu_d tanh(v_s/v_latch) + mu_v v_s)`` and
  ``(F_x, F_z) = -u |F_h| / (v_s + 1e-4)``.

The resultant moment is taken about a reference point (the midfoot-superior marker's
projection on the floor in GCP) with the original's planar lever arm
``(x_j - x_ref, 0, z_j - z_ref)``: the springs are treated as lying on the floor.

Parameter vector (``CONTACT_PARAMETERS`` order): damping factor D (s/m), dynamic friction
coefficient mu_d, viscous friction coefficient mu_v (s/m), resting spring length L0 (m),
latching velocity v_latch (m/s), belt speed (m/s; 0 overground).

Use in Treatment Optimization
-----------------------------
:class:`ContactSurfaceModel` holds one surface (from an ``.osimx`` ``RCNLContactSurface``)
and builds, for a :class:`~nmsm.model.casadi_model.CasadiModel`, SX functions of one frame:

* :meth:`ContactSurfaceModel.spring_kinematics_function` ``(q, qdot[, p]) -> (positions
  3 x n, velocities 3 x n)``;
* :meth:`ContactSurfaceModel.ground_reactions_function` ``(q, qdot[, p]) -> (force 3,
  moment 3 about the projected midfoot-superior marker, spring forces 3 x n)``;
* :meth:`ContactSurfaceModel.body_loads_function` ``(q, qdot[, p]) -> loads 9 x 2``
  (force N, point m, torque N m per body, ground) for ``[hindfoot, toes]``, ready for
  ``CasadiModel.inverse_dynamics_function(load_bodies=surface.bodies)``.

Example::

    surface = ContactSurfaceModel.from_osimx(read_osimx("subject_gcp.osimx").contact_surfaces[0], model)
    loads = surface.body_loads_function(cm)              # SX function of one frame
    tau = cm.inverse_dynamics_function(load_bodies=surface.bodies)(q, qd, qdd, loads(q, qd))
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import ModelError

#: order of the scalar contact parameters in :func:`contact_function`'s ``parameters`` input
CONTACT_PARAMETERS = (
    "damping_factor",
    "dynamic_friction_coefficient",
    "viscous_friction_coefficient",
    "resting_spring_length",
    "latching_velocity",
    "belt_speed",
)

#: slope (N/m) of the out-of-contact branch of the vertical spring force
K_LOW = 0.1
#: offset (m) of the contact transition
H_OFFSET = 1e-3
#: curvature (m) of the contact transition
CURVATURE = 1e-3
#: height (m) above the resting length where the out-of-contact force reaches zero
Y_MAX = 1e-2
#: clamp (m) of the height variable (``0.7 tanh(y / 0.7)``)
HEIGHT_CLAMP = 0.7
#: slip speed (m/s) added to the denominator of the friction direction
SLIP_OFFSET = 1e-4
#: slip speeds (m/s) below this count as zero
SLIP_ZERO = 1e-10


def _log_cosh(x: Any) -> Any:
    """``log(cosh(x))`` without overflow: ``|x| + log(1 + exp(-2|x|)) - log 2``."""
    ax = cs.fabs(x)
    return ax + cs.log1p(cs.exp(-2.0 * ax)) - np.log(2.0)


def elastic_force(height: Any, spring_constant: Any, resting_length: Any) -> Any:
    """Undamped vertical force ``F_el`` (N) of springs at ``height`` (m), elementwise."""
    y = HEIGHT_CLAMP * cs.tanh((height - resting_length) / HEIGHT_CLAMP)
    v = (spring_constant + K_LOW) / (spring_constant - K_LOW)
    s = (spring_constant - K_LOW) / 2.0
    offset = s * (v * Y_MAX - CURVATURE * _log_cosh((Y_MAX + H_OFFSET) / CURVATURE))
    return -s * (v * y - CURVATURE * _log_cosh((y + H_OFFSET) / CURVATURE)) + offset


def vertical_forces(height: Any, vertical_velocity: Any, spring_constant: Any, resting_length: Any,
                    damping_factor: Any) -> Any:
    """Vertical spring forces ``F_y`` (N): ``F_el (1 - D ydot)``, elementwise."""
    return elastic_force(height, spring_constant, resting_length) * (1.0 - damping_factor * vertical_velocity)


def friction_forces(vertical_force: Any, x_velocity: Any, z_velocity: Any, belt_speed: Any,
                    dynamic_friction: Any, viscous_friction: Any, latching_velocity: Any) -> tuple[Any, Any]:
    """Horizontal spring forces ``(F_x, F_z)`` (N), elementwise (module docstring)."""
    ux = x_velocity + belt_speed
    uz = z_velocity
    speed_squared = ux * ux + uz * uz
    slip = cs.if_else(speed_squared < SLIP_ZERO**2, 0, cs.sqrt(speed_squared), True)
    magnitude = vertical_force * (dynamic_friction * cs.tanh(slip / latching_velocity) + viscous_friction * slip)
    scale = -magnitude / (slip + SLIP_OFFSET)
    return ux * scale, uz * scale


def unit_loads(positions: Any, velocities: Any, parameters: Any, reference: Any) -> tuple[Any, Any]:
    """The resultant as a linear function of the spring constants: ``(A 6 x n, b 6 x 1)``
    with ``[force; moment] = A K + b`` (N, N m), exactly :func:`contact_function`.

    ``F_el`` is linear in ``K``: with ``y`` the clamped height and
    ``g(y) = (c/2)(lc((y + h_off)/c) - lc((y_max + h_off)/c))``,
    ``F_el = K (y_max - y)/2 + K g + k_low ((y_max - y)/2 - g)``; damping and friction
    multiply it by factors independent of ``K``. Exposing ``A`` lets a caller form the
    resultant with a matrix product, so derivatives with respect to ``K`` never pass
    through the per-spring expressions (much cheaper Jacobians over many frames).
    """
    damping, mu_d, mu_v, rest, latch, belt = (parameters[i] for i in range(6))
    y = HEIGHT_CLAMP * cs.tanh((positions[1, :] - rest) / HEIGHT_CLAMP)
    g = 0.5 * CURVATURE * (_log_cosh((y + H_OFFSET) / CURVATURE) - _log_cosh((Y_MAX + H_OFFSET) / CURVATURE))
    linear = 0.5 * (Y_MAX - y)
    per_k = linear + g
    constant = K_LOW * (linear - g)
    damp = 1.0 - damping * velocities[1, :]
    gx, gz = friction_forces(damp, velocities[0, :], velocities[2, :], belt, mu_d, mu_v, latch)
    unit = cs.vertcat(gx, damp, gz)  # force per unit F_el, (3, n)
    n = positions.shape[1]
    dx = positions[0, :] - cs.repmat(reference[0], 1, n)
    dz = positions[2, :] - cs.repmat(reference[2], 1, n)
    unit_moment = cs.vertcat(-dz * unit[1, :], dz * unit[0, :] - dx * unit[2, :], dx * unit[1, :])
    unit_load = cs.vertcat(unit, unit_moment)  # (6, n)
    a = unit_load * cs.repmat(per_k, 6, 1)
    b = cs.sum2(unit_load * cs.repmat(constant, 6, 1))
    return a, b


def spring_forces(positions: Any, velocities: Any, spring_constants: Any, parameters: Any) -> Any:
    """Forces (3, n) of ``n`` springs on their bodies (N, ground).

    ``positions``/``velocities`` (3, n) in ground (m, m/s); ``spring_constants`` (n,)
    N/m; ``parameters`` (6,) in :data:`CONTACT_PARAMETERS` order.
    """
    damping, mu_d, mu_v, rest, latch, belt = (parameters[i] for i in range(6))
    k = cs.reshape(spring_constants, 1, -1)
    fy = vertical_forces(positions[1, :], velocities[1, :], k, rest, damping)
    fx, fz = friction_forces(fy, velocities[0, :], velocities[2, :], belt, mu_d, mu_v, latch)
    return cs.vertcat(fx, fy, fz)


def planar_moment(positions: Any, forces: Any, reference: Any) -> Any:
    """Moment (3,) N m of ``forces`` (3, n) at ``positions`` (3, n) about ``reference`` (3,)
    with lever arms ``(x - x_ref, 0, z - z_ref)`` (module docstring)."""
    n = positions.shape[1]
    dx = positions[0, :] - cs.repmat(reference[0], 1, n)
    dz = positions[2, :] - cs.repmat(reference[2], 1, n)
    fx, fy, fz = forces[0, :], forces[1, :], forces[2, :]
    mx = cs.sum2(-dz * fy)
    my = cs.sum2(dz * fx - dx * fz)
    mz = cs.sum2(dx * fy)
    return cs.vertcat(mx, my, mz)


def contact_function(n_springs: int, name: str = "foot_contact") -> cs.Function:
    """SX Function of one frame::

        (positions 3 x n, velocities 3 x n, spring_constants n x 1, parameters 6 x 1,
         reference 3 x 1) -> (force 3 x 1, moment 3 x 1, spring_forces 3 x n)

    ``force`` is the total ground reaction (N), ``moment`` its moment about ``reference``
    (N m, planar lever arms), ``spring_forces`` the per-spring forces (N), all in ground.
    """
    positions = cs.SX.sym("positions", 3, n_springs)
    velocities = cs.SX.sym("velocities", 3, n_springs)
    k = cs.SX.sym("spring_constants", n_springs)
    parameters = cs.SX.sym("parameters", len(CONTACT_PARAMETERS))
    reference = cs.SX.sym("reference", 3)
    forces = spring_forces(positions, velocities, k, parameters)
    total = cs.sum2(forces)
    moment = planar_moment(positions, forces, reference)
    return cs.Function(name, [positions, velocities, k, parameters, reference], [total, moment, forces],
                       ["positions", "velocities", "spring_constants", "parameters", "reference"],
                       ["force", "moment", "spring_forces"])


@attrs.frozen
class ContactParameters:
    """Scalar properties of a contact surface (see :data:`CONTACT_PARAMETERS`)."""

    damping_factor: float  #: s/m
    dynamic_friction_coefficient: float
    viscous_friction_coefficient: float  #: s/m
    resting_spring_length: float  #: m
    latching_velocity: float  #: m/s
    belt_speed: float = 0.0  #: m/s

    def vector(self) -> np.ndarray:
        """The (6,) parameter vector in :data:`CONTACT_PARAMETERS` order."""
        return np.array([getattr(self, name) for name in CONTACT_PARAMETERS], dtype=float)


@attrs.frozen
class ContactSurfaceModel:
    """One foot's springs and contact properties, ready to be attached to a model.

    ``spring_bodies`` (n,) body names; ``spring_locations`` (n, 3) m in those bodies'
    frames; ``spring_constants`` (n,) N/m. ``hindfoot_body``/``toes_body`` are the two
    foot segments; ``midfoot_superior_marker`` names the moment reference marker.
    """

    hindfoot_body: str
    toes_body: str
    spring_bodies: tuple[str, ...]
    spring_locations: np.ndarray
    spring_constants: np.ndarray
    parameters: ContactParameters
    midfoot_superior_marker: str

    @property
    def n_springs(self) -> int:
        return len(self.spring_bodies)

    @property
    def bodies(self) -> tuple[str, str]:
        """``(hindfoot, toes)``: the bodies receiving the contact loads, in load order."""
        return (self.hindfoot_body, self.toes_body)

    @classmethod
    def from_osimx(cls, surface: Any, model: Any) -> ContactSurfaceModel:
        """From an :class:`~nmsm.io.osimx.OsimxContactSurface` and the :class:`Model`
        it belongs to (the toes body is the child of the hindfoot's one-coordinate joint)."""
        toes = toes_body_of(model, surface.hindfoot_body)
        if surface.midfoot_superior_marker not in model.marker_names:  # the moment reference (was found later)
            raise ModelError(f"no marker '{surface.midfoot_superior_marker}'", file=model.file,
                             element="<midfoot_superior_marker>", expected="a marker of the model")
        bodies = tuple(s.parent_body for s in surface.springs)
        for spring in surface.springs:
            if spring.parent_body not in (surface.hindfoot_body, toes):
                raise ModelError(f"spring '{spring.name}' is on body '{spring.parent_body}', not on the foot",
                                 file=model.file, element="<parent_body>",
                                 expected=f"springs on '{surface.hindfoot_body}' or '{toes}'")
        return cls(
            hindfoot_body=surface.hindfoot_body,
            toes_body=toes,
            spring_bodies=bodies,
            spring_locations=np.array([s.location for s in surface.springs], dtype=float).reshape(-1, 3),
            spring_constants=np.array([s.spring_constant for s in surface.springs], dtype=float),
            parameters=ContactParameters(
                damping_factor=surface.damping_factor,
                dynamic_friction_coefficient=surface.dynamic_friction_coefficient,
                viscous_friction_coefficient=surface.viscous_friction_coefficient,
                resting_spring_length=surface.resting_spring_length,
                latching_velocity=surface.latching_velocity,
                belt_speed=surface.belt_speed,
            ),
            midfoot_superior_marker=surface.midfoot_superior_marker,
        )

    # ------------------------------------------------------------------ with a CasadiModel
    def _inputs(self, casadi_model: Any) -> tuple[list[Any], list[Any]]:
        q, qd = casadi_model.q, casadi_model.qdot
        args = [q, qd, casadi_model.p] if casadi_model.has_parameters else [q, qd]
        names = ["q", "qdot", "p"] if casadi_model.has_parameters else ["q", "qdot"]
        return args, names

    def _spring_kinematics(self, casadi_model: Any) -> tuple[Any, Any]:
        args, _ = self._inputs(casadi_model)
        return self.spring_kinematics(casadi_model, *args)

    def spring_kinematics(self, casadi_model: Any, q: Any, qdot: Any, *parameters: Any) -> tuple[Any, Any]:
        """``(positions 3 x n, velocities 3 x n)`` (m, m/s, ground) of the springs at ``q``,
        ``qdot`` (and the model's parameters, if it has any), in spring order; each body's
        motion is computed once for its springs."""
        bodies = self.spring_bodies
        positions, velocities = [None] * len(bodies), [None] * len(bodies)
        for body in dict.fromkeys(bodies):
            index = [j for j, b in enumerate(bodies) if b == body]
            x, v = casadi_model.body_points_function(body, self.spring_locations[index].T)(q, qdot, *parameters)
            for k, j in enumerate(index):
                positions[j], velocities[j] = x[:, k], v[:, k]
        return cs.horzcat(*positions), cs.horzcat(*velocities)

    def spring_kinematics_function(self, casadi_model: Any) -> cs.Function:
        """``(q, qdot[, p]) -> (positions 3 x n, velocities 3 x n)`` of the springs (ground)."""
        args, names = self._inputs(casadi_model)
        positions, velocities = self._spring_kinematics(casadi_model)
        return cs.Function("spring_kinematics", args, [positions, velocities], names, ["positions", "velocities"])

    def ground_reactions_function(self, casadi_model: Any) -> cs.Function:
        """``(q, qdot[, p]) -> (force 3, moment 3, spring_forces 3 x n)``: the surface's
        ground reaction (N, ground) and its moment (N m) about the midfoot-superior marker
        projected on the floor, with this surface's stored parameters."""
        args, names = self._inputs(casadi_model)
        positions, velocities = self._spring_kinematics(casadi_model)
        marker = casadi_model.marker_function([self.midfoot_superior_marker])(*args[:1], *args[2:])
        reference = cs.vertcat(marker[0], 0, marker[2])
        force, moment, forces = contact_function(self.n_springs)(
            positions, velocities, cs.DM(self.spring_constants), cs.DM(self.parameters.vector()), reference)
        return cs.Function("ground_reactions", args, [force, moment, forces], names,
                           ["force", "moment", "spring_forces"])

    def body_loads_function(self, casadi_model: Any) -> cs.Function:
        """``(q, qdot[, p]) -> loads 9 x 2``: for ``(hindfoot, toes)`` the summed spring force
        (N), the body origin (m) and the springs' torque about it (N m), all in ground."""
        args, names = self._inputs(casadi_model)
        positions, velocities = self._spring_kinematics(casadi_model)
        forces = spring_forces(positions, velocities, cs.DM(self.spring_constants), cs.DM(self.parameters.vector()))
        extra = args[2:]
        columns = []
        for body in self.bodies:
            _, origin = casadi_model.body_pose_function(body)(args[0], *extra)
            total = cs.SX.zeros(3, 1)
            torque = cs.SX.zeros(3, 1)
            for j, spring_body in enumerate(self.spring_bodies):
                if spring_body != body:
                    continue
                total = total + forces[:, j]
                torque = torque + cs.cross(positions[:, j] - origin, forces[:, j])
            columns.append(cs.vertcat(total, origin, torque))
        return cs.Function("contact_loads", args, [cs.horzcat(*columns)], names, ["loads"])


def toes_body_of(model: Any, hindfoot_body: str) -> str:
    """The toes body: child of the joint whose parent is ``hindfoot_body`` and that has
    exactly one coordinate (the two-segment foot GCP requires)."""
    candidates = [j for j in model.joints if j.parent_body == hindfoot_body and len(j.coordinates) == 1]
    if hindfoot_body not in model.bodies:
        raise ModelError(f"no body '{hindfoot_body}'", file=model.file, element="<hindfoot_body>",
                         expected="a body of the model")
    if len(candidates) != 1:
        found = ", ".join(f"{j.name} ({len(j.coordinates)} coordinates)" for j in model.joints
                          if j.parent_body == hindfoot_body) or "none"
        raise ModelError(
            f"body '{hindfoot_body}' is not the hindfoot of a two-segment foot: joints with it as parent: {found}",
            file=model.file, element="<hindfoot_body>",
            expected="exactly one child joint of the hindfoot with one coordinate (the toes joint)")
    return candidates[0].child_body


def stack_parameters(values: Sequence[Any]) -> Any:
    """A (6, 1) CasADi column from six scalars (numbers or expressions) in
    :data:`CONTACT_PARAMETERS` order."""
    if len(values) != len(CONTACT_PARAMETERS):
        raise ValueError(f"expected {len(CONTACT_PARAMETERS)} contact parameters, got {len(values)}")
    return cs.vertcat(*values)

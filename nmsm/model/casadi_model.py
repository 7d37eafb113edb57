"""The model as CasADi functions: :class:`CasadiModel`.

Conventions
-----------
* ``q`` is the full coordinate vector in the model's coordinate order
  (``model.coordinate_names``, OpenSim's CoordinateSet order), dependent (coupled)
  coordinates included; rad for rotational, m for translational coordinates.
* Speeds ``qdot`` are OpenSim's generalized speeds: the coordinate rates, except for the
  rotational coordinates of a FreeJoint/BallJoint (angular velocity of the child frame in
  the parent frame, expressed in the parent frame). ``qddot`` are their rates.
* Accelerations and inverse dynamics reproduce OpenSim (Simbody), including its
  velocity-product terms of CustomJoints whose coordinate drives several rotation axes,
  which Simbody approximates (``custom_joint_bias="opensim"``, the default); pass
  ``custom_joint_bias="exact"`` for the exact derivative (see :mod:`nmsm.model.joint_motion`).
  Positions, velocities, the mass matrix and gravity terms are identical in both modes.
* Everything is expressed in ground. Points on a body are given in the body frame with
  the file's geometry (a body scale parameter scales them).
* Functions are SX functions of one frame (one state); ``map`` them over frames inside MX
  problems (``f.map(n, "thread", 2)``; see :meth:`CasadiModel.mapped`).
* With model parameters (:class:`~nmsm.model.parameters.ModelParameters`) every Function
  takes an extra last input ``p`` (``parameters.symbols`` order); the expression methods
  take ``p=`` and default to the parameter symbols themselves (valid for SX arguments).

Example::

    model = load_model("RCNL2024.osim")
    cm = CasadiModel(model)
    R, p = cm.body_pose("calcn_r", q)                 # q: SX/MX/DM (n,)
    x = cm.point_in_ground("calcn_r", [0.1, 0, 0], q)
    markers = cm.marker_function()                    # q -> 3 x n_markers
    tau = cm.inverse_dynamics_function(load_bodies=["calcn_r", "calcn_l"])
    tau(q, qd, qdd, loads)                            # loads: 9 x 2 (force, point, torque)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as cs
import numpy as np

from nmsm.core.function_names import function_name
from nmsm.core.threads import SOLVER_THREADS
from nmsm.errors import ModelError
from nmsm.model.components import GROUND, CoordinateActuator, Model, PointActuator, TorqueActuator
from nmsm.model.contact_smooth_sphere import ContactResult, contact_force
from nmsm.model.coordinates import CoordinateMap
from nmsm.model.dynamics import GroundLoad, inverse_dynamics
from nmsm.model.kinematics import BodyState, TreeKinematics
from nmsm.model.parameters import ModelParameters
from nmsm.model.spatial import body_xyz_angles


class CasadiModel:
    """CasADi functions of an OpenSim model (see module docstring for conventions)."""

    def __init__(self, model: Model, parameters: ModelParameters | None = None, *,
                 custom_joint_bias: str = "opensim") -> None:
        if parameters is not None and parameters.model is not model:
            raise ValueError("the ModelParameters were made for another Model object")
        self.model = model
        self.parameters = parameters if parameters is not None else ModelParameters(model)
        self.kinematics = TreeKinematics(model, self.parameters, custom_joint_bias)
        self.coordinates = CoordinateMap(model)
        self.n = len(model.coordinates)
        self.q = cs.SX.sym("q", self.n)
        self.qdot = cs.SX.sym("qdot", self.n)
        self.qddot = cs.SX.sym("qddot", self.n)
        self.p = self.parameters.symbols
        self._positions: dict[str, BodyState] | None = None
        self._cache: dict[Any, cs.Function] = {}

    # ------------------------------------------------------------------ names
    @property
    def coordinate_names(self) -> list[str]:
        return self.model.coordinate_names

    @property
    def has_parameters(self) -> bool:
        return self.parameters.size > 0

    def coordinate_index(self, name: str) -> int:
        try:
            return self.kinematics.coordinate_index[name]
        except KeyError:
            raise ModelError(f"no coordinate '{name}'", file=self.model.file,
                             expected="a coordinate of the model") from None

    def _check_body(self, body: str) -> None:
        if body != GROUND and body not in self.model.bodies:
            raise ModelError(f"no body '{body}'", file=self.model.file,
                             expected="one of " + ", ".join(self.model.bodies))

    # ------------------------------------------------------------------ plumbing
    def _inputs(self, *symbols: Any) -> list[Any]:
        return [*symbols, self.p] if self.has_parameters else list(symbols)

    def _input_names(self, *names: str) -> list[str]:
        return [*names, "p"] if self.has_parameters else list(names)

    def _args(self, args: Sequence[Any], p: Any) -> list[Any]:
        if not self.has_parameters:
            return list(args)
        if p is None:
            if any(isinstance(a, cs.MX) for a in args):
                raise ValueError("this model has parameters: pass p= (an MX vector) with MX arguments")
            p = self.p
        return [*args, p]

    def _position_states(self) -> dict[str, BodyState]:
        if self._positions is None:
            self._positions = self.kinematics.forward(self.q)
        return self._positions

    def _function(self, key: Any, build: Any) -> cs.Function:
        f = self._cache.get(key)
        if f is None:
            f = build()
            self._cache[key] = f
        return f

    def mapped(self, function: cs.Function, n_frames: int, workers: int = SOLVER_THREADS) -> cs.Function:
        """``function`` evaluated over ``n_frames`` frames (columns), in parallel threads."""
        return function.map(n_frames, "thread", workers)

    # ------------------------------------------------------------------ kinematics
    def body_pose_function(self, body: str) -> cs.Function:
        """``(q[, p]) -> (R 3x3 body->ground, origin 3x1 m)`` (outputs "R", "origin") of ``body``."""
        self._check_body(body)

        def build() -> cs.Function:
            st = self._position_states()[body] if body != GROUND else BodyState(cs.DM.eye(3), cs.DM.zeros(3, 1))
            return cs.Function(function_name("pose", body), self._inputs(self.q), [st.R, st.p],
                               self._input_names("q"), ["R", "origin"])

        return self._function(("pose", body), build)

    def body_pose(self, body_name: str, q: Any, p: Any = None) -> tuple[Any, Any]:
        """Rotation (3x3, body to ground) and origin (3x1, m, ground) of a body at ``q``."""
        rotation, origin = self.body_pose_function(body_name)(*self._args([q], p))
        return rotation, origin

    def point_function(self, body: str) -> cs.Function:
        """``(q, x_local[, p]) -> x_ground`` for a point fixed in ``body`` (file geometry, m)."""
        self._check_body(body)

        def build() -> cs.Function:
            x = cs.SX.sym("x_local", 3)
            st = self._position_states()[body] if body != GROUND else BodyState(cs.DM.eye(3), cs.DM.zeros(3, 1))
            scaled = x * self.kinematics.scale(body) if body != GROUND else x
            return cs.Function(function_name("point", body), self._inputs(self.q, x), [st.p + cs.mtimes(st.R, scaled)],
                               self._input_names("q", "x_local"), ["x"])

        return self._function(("point", body), build)

    def point_in_ground(self, body_name: str, local_point: Any, q: Any, p: Any = None) -> Any:
        """Position (3x1, m, ground) of a point given in ``body_name``'s frame."""
        point = local_point if isinstance(local_point, (cs.SX, cs.MX, cs.DM)) else cs.DM(np.asarray(local_point, float))
        return self.point_function(body_name)(*self._args([q, point], p))

    def frame_pose_function(self, frame_path: str) -> cs.Function:
        """``(q[, p]) -> (R, origin)`` of any frame (body, ground or offset frame path)."""
        if frame_path not in self.model.frames:
            raise ModelError(f"no frame '{frame_path}'", file=self.model.file, expected="a frame path of the model")

        def build() -> cs.Function:
            frame = self.model.frames[frame_path]
            body = frame.base_body
            st = self._position_states()[body] if body != GROUND else BodyState(cs.DM.eye(3), cs.DM.zeros(3, 1))
            r_local, p_local = self.kinematics.frame_in_base(frame_path)
            return cs.Function("frame_pose", self._inputs(self.q),
                               [cs.mtimes(st.R, r_local), st.p + cs.mtimes(st.R, p_local)],
                               self._input_names("q"), ["R", "origin"])

        return self._function(("frame", frame_path), build)

    def frame_pose(self, frame_path: str, q: Any, p: Any = None) -> tuple[Any, Any]:
        rotation, origin = self.frame_pose_function(frame_path)(*self._args([q], p))
        return rotation, origin

    def marker_function(self, markers: Sequence[str] | None = None) -> cs.Function:
        """``(q[, p]) -> 3 x n_markers`` positions (m, ground), model marker order by default."""
        names = tuple(markers) if markers is not None else tuple(self.model.marker_names)
        index = {m.name: i for i, m in enumerate(self.model.markers)}
        missing = [n for n in names if n not in index]
        if missing:
            raise ModelError(f"no markers {', '.join(missing)}", file=self.model.file, expected="markers of the model")

        def build() -> cs.Function:
            states = self._position_states()
            columns = []
            for name in names:
                i = index[name]
                marker = self.model.markers[i]
                st = states[marker.body] if marker.body != GROUND else BodyState(cs.DM.eye(3), cs.DM.zeros(3, 1))
                columns.append(st.p + cs.mtimes(st.R, self.kinematics.marker_in_body(i)))
            out = cs.horzcat(*columns) if columns else cs.SX(3, 0)
            return cs.Function("markers", self._inputs(self.q), [out], self._input_names("q"), ["markers"])

        return self._function(("markers", names), build)

    def marker_positions(self, q: Any, p: Any = None) -> Any:
        """Marker positions (3 x n_markers, m, ground) at ``q``."""
        return self.marker_function()(*self._args([q], p))

    def body_origins_function(self) -> cs.Function:
        """``(q[, p]) -> 3 x n_bodies`` body origins (model body order)."""

        def build() -> cs.Function:
            states = self._position_states()
            out = cs.horzcat(*[states[b].p for b in self.model.bodies])
            return cs.Function("body_origins", self._inputs(self.q), [out], self._input_names("q"), ["origins"])

        return self._function("origins", build)

    def body_orientation_function(self, body: str) -> cs.Function:
        """``(q[, p]) -> body-fixed X-Y-Z angles`` (rad) of ``body`` in ground."""
        self._check_body(body)

        def build() -> cs.Function:
            st = self._position_states()[body]
            return cs.Function(function_name("angles", body), self._inputs(self.q), [body_xyz_angles(st.R)],
                               self._input_names("q"), ["angles"])

        return self._function(("angles", body), build)

    def center_of_mass_function(self) -> cs.Function:
        """``(q[, p]) -> whole-body centre of mass`` (3x1, m, ground)."""

        def build() -> cs.Function:
            states = self._position_states()
            total: Any = 0
            weighted: Any = cs.DM.zeros(3, 1)
            for name in self.model.bodies:
                mass, com, _ = self.kinematics.body_mass_properties(name)
                st = states[name]
                weighted = weighted + mass * (st.p + cs.mtimes(st.R, com))
                total = total + mass
            return cs.Function("center_of_mass", self._inputs(self.q), [weighted / total],
                               self._input_names("q"), ["com"])

        return self._function("com", build)

    def point_velocity_function(self, body: str) -> cs.Function:
        """``(q, qdot, x_local[, p]) -> velocity`` (3x1, m/s, ground) of a point fixed in ``body``."""
        self._check_body(body)

        def build() -> cs.Function:
            x = cs.SX.sym("x_local", 3)
            st = self.kinematics.forward(self.q, self.qdot)[body]
            r = cs.mtimes(st.R, x * self.kinematics.scale(body))
            return cs.Function(function_name("velocity", body), self._inputs(self.q, self.qdot, x), [st.v + cs.cross(st.w, r)],
                               self._input_names("q", "qdot", "x_local"), ["v"])

        return self._function(("velocity", body), build)

    def body_points_function(self, body: str, locations: Any) -> cs.Function:
        """``(q, qdot[, p]) -> (positions 3 x k, velocities 3 x k)`` (m, m/s, ground) of ``k``
        points fixed in ``body``; ``locations`` (3, k) in the body frame (file geometry, m).

        The body's pose and motion are computed once for all points, so the function grows
        with ``k`` by a few operations a point (one :meth:`point_function` call per point
        repeats the whole kinematic chain)."""
        self._check_body(body)
        local = np.asarray(locations, float).reshape(3, -1)

        def build() -> cs.Function:
            st = self.kinematics.forward(self.q, self.qdot)[body]
            lever = cs.mtimes(st.R, cs.DM(local) * self.kinematics.scale(body))
            n = local.shape[1]
            positions = cs.repmat(st.p, 1, n) + lever
            velocities = cs.repmat(st.v, 1, n) + cs.horzcat(*[cs.cross(st.w, lever[:, j]) for j in range(n)])
            return cs.Function(function_name("points", body), self._inputs(self.q, self.qdot), [positions, velocities],
                               self._input_names("q", "qdot"), ["positions", "velocities"])

        return self._function(("points", body, local.tobytes()), build)

    def marker_velocity_function(self) -> cs.Function:
        """``(q, qdot[, p]) -> 3 x n_markers`` marker velocities (m/s, ground)."""

        def build() -> cs.Function:
            states = self.kinematics.forward(self.q, self.qdot)
            columns = []
            for i, marker in enumerate(self.model.markers):
                if marker.body == GROUND:
                    columns.append(cs.DM.zeros(3, 1))
                    continue
                st = states[marker.body]
                columns.append(st.v + cs.cross(st.w, cs.mtimes(st.R, self.kinematics.marker_in_body(i))))
            out = cs.horzcat(*columns) if columns else cs.SX(3, 0)
            return cs.Function("marker_velocities", self._inputs(self.q, self.qdot), [out],
                               self._input_names("q", "qdot"), ["velocities"])

        return self._function("marker_velocities", build)

    # ------------------------------------------------------------------ dynamics
    def _contact_results(self, states: dict[str, BodyState]) -> list[ContactResult]:
        return [contact_force(self.kinematics, force, states) for force in self.model.contact_forces
                if force.applies_force]

    def contact_force_function(self) -> cs.Function:
        """``(q, qdot[, p]) -> (forces 3 x k, points 3 x k)``: each SmoothSphereHalfSpaceForce's
        force on its sphere's body (N, ground) and the contact point (m, ground)."""

        def build() -> cs.Function:
            states = self.kinematics.forward(self.q, self.qdot)
            results = self._contact_results(states)
            forces = cs.horzcat(*[r.force for r in results]) if results else cs.SX(3, 0)
            points = cs.horzcat(*[r.point for r in results]) if results else cs.SX(3, 0)
            return cs.Function("contact_forces", self._inputs(self.q, self.qdot), [forces, points],
                               self._input_names("q", "qdot"), ["forces", "points"])

        return self._function("contact", build)

    def inverse_dynamics(self, q: Any, qdot: Any, qddot: Any, loads: Sequence[GroundLoad] = (),
                         generalized_forces: Any = None, *, include_contact: bool = False,
                         gravity: bool = True) -> Any:
        """Generalized forces (SX, ``(n, 1)``) from SX inputs (see :mod:`nmsm.model.dynamics`)."""
        loads = list(loads)
        if include_contact:
            states = self.kinematics.forward(q, qdot)
            for r in self._contact_results(states):
                loads.append(GroundLoad(r.sphere_body, r.force, r.point, cs.DM.zeros(3, 1)))
                loads.append(GroundLoad(r.half_space_body, -r.force, r.point, cs.DM.zeros(3, 1)))
        return inverse_dynamics(self.kinematics, q, qdot, qddot, loads, generalized_forces, gravity)

    def inverse_dynamics_function(self, load_bodies: Sequence[str] = (), *, applied_forces: bool = False,
                                  include_contact: bool = False, gravity: bool = True) -> cs.Function:
        """Inverse dynamics as an SX Function of one frame.

        Inputs: ``q, qdot, qddot`` (n), then ``loads`` (9 x len(load_bodies): force N,
        point m, torque N m, all in ground, one column per entry of ``load_bodies``) when
        ``load_bodies`` is given, ``tau_applied`` (n, generalized forces already applied,
        subtracted) when ``applied_forces``, and ``p`` with parameters.
        Output ``tau`` (n): generalized forces in model coordinate order.
        ``include_contact`` adds the model's SmoothSphereHalfSpaceForce contact forces.
        """
        bodies = tuple(load_bodies)
        for b in bodies:
            self._check_body(b)

        def build() -> cs.Function:
            inputs = [self.q, self.qdot, self.qddot]
            names = ["q", "qdot", "qddot"]
            loads = []
            if bodies:
                values = cs.SX.sym("loads", 9, len(bodies))
                inputs.append(values)
                names.append("loads")
                loads = [GroundLoad(b, values[0:3, k], values[3:6, k], values[6:9, k]) for k, b in enumerate(bodies)]
            applied = None
            if applied_forces:
                applied = cs.SX.sym("tau_applied", self.n)
                inputs.append(applied)
                names.append("tau_applied")
            tau = self.inverse_dynamics(self.q, self.qdot, self.qddot, loads, applied,
                                        include_contact=include_contact, gravity=gravity)
            return cs.Function("inverse_dynamics", self._inputs(*inputs), [tau], self._input_names(*names), ["tau"])

        return self._function(("id", bodies, applied_forces, include_contact, gravity), build)

    def inverse_dynamics_jacobian_function(self, load_bodies: Sequence[str] = (), *,
                                           include_contact: bool = False) -> cs.Function:
        """``(q, qdot, qddot[, loads][, p]) -> (tau, dtau/dq, dtau/dqdot, dtau/dqddot)``: inverse
        dynamics and its exact Jacobian blocks (n x n each; the last is the mass matrix)."""
        bodies = tuple(load_bodies)

        def build() -> cs.Function:
            f = self.inverse_dynamics_function(bodies, include_contact=include_contact)
            inputs = [self.q, self.qdot, self.qddot]
            names = ["q", "qdot", "qddot"]
            if bodies:
                loads = cs.SX.sym("loads", 9, len(bodies))
                inputs.append(loads)
                names.append("loads")
            tau = f(*self._args(inputs, None))
            blocks = [cs.jacobian(tau, v) for v in (self.q, self.qdot, self.qddot)]
            return cs.Function("inverse_dynamics_jacobian", self._inputs(*inputs), [tau, *blocks],
                               self._input_names(*names), ["tau", "dtau_dq", "dtau_dqdot", "dtau_dqddot"])

        return self._function(("id_jacobian", bodies, include_contact), build)

    def mass_matrix_function(self) -> cs.Function:
        """``(q[, p]) -> M`` (n x n) mass matrix."""

        def build() -> cs.Function:
            zero = cs.DM.zeros(self.n, 1)
            tau = inverse_dynamics(self.kinematics, self.q, zero, self.qddot, (), None, gravity=False)
            mass = cs.jacobian(tau, self.qddot)
            return cs.Function("mass_matrix", self._inputs(self.q), [mass], self._input_names("q"), ["M"])

        return self._function("mass", build)

    def forward_dynamics_function(self, load_bodies: Sequence[str] = (), *, include_contact: bool = False) -> cs.Function:
        """``(q, qdot, tau[, loads][, p]) -> qddot``: accelerations from generalized forces
        (mass-matrix solve, an MX Function over SX pieces)."""
        bodies = tuple(load_bodies)

        def build() -> cs.Function:
            bias_f = self.inverse_dynamics_function(bodies, include_contact=include_contact)
            mass_f = self.mass_matrix_function()
            q = cs.MX.sym("q", self.n)
            qd = cs.MX.sym("qdot", self.n)
            tau = cs.MX.sym("tau", self.n)
            inputs = [q, qd, tau]
            names = ["q", "qdot", "tau"]
            bias_args = [q, qd, cs.MX.zeros(self.n, 1)]
            if bodies:
                loads = cs.MX.sym("loads", 9, len(bodies))
                inputs.append(loads)
                names.append("loads")
                bias_args.append(loads)
            mass_args = [q]
            if self.has_parameters:
                p = cs.MX.sym("p", self.parameters.size)
                inputs.append(p)
                names.append("p")
                bias_args.append(p)
                mass_args.append(p)
            rhs = tau - bias_f(*bias_args)
            qdd = cs.solve(mass_f(*mass_args), rhs, "qr")
            return cs.Function("forward_dynamics", inputs, [qdd], names, ["qddot"])

        return self._function(("fd", bodies, include_contact), build)

    def actuator_names(self) -> list[str]:
        return [a.name for a in self.model.actuators]

    def actuator_generalized_forces_function(self) -> cs.Function:
        """``(q, controls[, p]) -> tau`` (n): generalized forces of the model's actuators
        (CoordinateActuator, PointActuator, TorqueActuator; ``optimal_force * control``)."""

        def build() -> cs.Function:
            actuators = self.model.actuators
            controls = cs.SX.sym("controls", len(actuators))
            states = self._position_states()
            tau = cs.SX.zeros(self.n, 1)
            loads: list[GroundLoad] = []
            zero3 = cs.DM.zeros(3, 1)
            for k, act in enumerate(actuators):
                if not act.applies_force:
                    continue
                magnitude = act.optimal_force * controls[k]
                if isinstance(act, CoordinateActuator):
                    i = self.coordinate_index(act.coordinate)
                    tau[i] = tau[i] + magnitude
                elif isinstance(act, PointActuator):
                    st = states[act.body]
                    direction = cs.DM(act.direction / np.linalg.norm(act.direction))
                    force = magnitude * (direction if act.force_is_global else cs.mtimes(st.R, direction))
                    point = cs.DM(act.point) if act.point_is_global else st.p + cs.mtimes(st.R, cs.DM(act.point))
                    loads.append(GroundLoad(act.body, force, point, zero3))
                elif isinstance(act, TorqueActuator):
                    axis = cs.DM(act.axis / np.linalg.norm(act.axis))
                    if not act.torque_is_global:
                        axis = cs.mtimes(states[act.body_a].R, axis)
                    torque = magnitude * axis
                    loads.append(GroundLoad(act.body_a, zero3, states[act.body_a].p if act.body_a != GROUND else zero3, torque))
                    loads.append(GroundLoad(act.body_b, zero3, states[act.body_b].p if act.body_b != GROUND else zero3, -torque))
            if loads:
                zero = cs.DM.zeros(self.n, 1)
                tau = tau - inverse_dynamics(self.kinematics, self.q, zero, zero, loads, None, gravity=False)
            return cs.Function("actuator_forces", self._inputs(self.q, controls), [tau],
                               self._input_names("q", "controls"), ["tau"])

        return self._function("actuators", build)

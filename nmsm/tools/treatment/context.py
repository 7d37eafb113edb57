"""The context through which Treatment Optimization terms read modeled and tracked quantities.

A term receives a :class:`TreatmentContext`. It is a :class:`GridView` of the *collocation
points* (``K`` rows: continuous costs and path constraints) and gives views of the phase's
``initial`` and ``final`` points (one row each: terminal constraints), plus problem-wide
quantities (final time, static parameters, synergy weights). Every quantity is a CasADi
MX expression computed lazily - only when a term asks for it - and cached per grid; model
quantities are per-point SX functions ``map``\\ ped over the grid's rows.

Quantities of a :class:`GridView` (``n`` = rows of the grid; SI units, radians):

=========================================  ============  =============================================
method                                     shape         meaning
=========================================  ============  =============================================
``time()``                                 (n, 1)  s     time of each row (``t_f * s``)
``normalized_time``                        (n,)          ``s`` in [0, 1] (numpy)
``coordinate(c)`` / ``speed(c)`` /         (n, 1)        q, q̇, q̈ of any model coordinate (state,
``acceleration(c)``                                      prescribed or coupler-dependent), rad|m
``positions()`` / ``speeds()`` /           (n, nq)       all coordinates, model order
``accelerations()``
``tracked_coordinate(c)`` / ``_speed`` /   (n, 1)        experimental reference (tracked IK spline)
``_acceleration``
``inverse_dynamics_load(load)``            (n, 1)  N·m|N inverse dynamics of the modeled motion;
                                                         ``load`` = ``<coord>_moment|_force`` or coord
``inverse_dynamics()``                     (n, nq)       all ID loads, model order
``tracked_load(load)``                     (n, 1)        experimental ID (tracked IDData)
``controller_load(load)``                  (n, 1)        what the controllers apply on the coordinate
                                                         (muscle moments + torque controls)
``marker_position(m)`` / ``_velocity(m)``  (n, 3)  m, m/s model marker in ground
``tracked_marker_position(m)`` / ``_vel``  (n, 3)        marker on the tracked kinematics
``body_orientation(b, sequence)``          (n, 3)  rad   body-fixed angles (``sequence`` order)
``tracked_body_orientation(b, sequence)``  (n, 3)        on the tracked kinematics
``control(name)``                          (n, 1)        a controller's control (torque N·m|N,
                                                         synergy activation, muscle activation)
``initial_control(name)``                  (n, 1)        its initial-guess reference
``muscle_activation(m)``                   (n, 1)        modeled activation (synergy or muscle
                                                         controller), 0..1
``tracked_muscle_activation(m)``           (n, 1)        reference activation (initial-guess dir)
``normalized_fiber_length(m)``             (n, 1)        l̃ of the Hill model
=========================================  ============  =============================================

Problem-wide (on :class:`TreatmentContext`): ``final_time`` (MX scalar, s),
``parameter(type)`` (MX column of a DO static parameter), ``synergy_weights(group)`` (MX
(S, M)), ``initial_synergy_weights(group)`` (numpy), ``integrate(values)`` (normalized-time
integral of a (K, m) expression), ``controller_names``, ``muscle_names``, ``model``.

Name checks (call from ``Term.bind``; they raise :class:`InputError` naming the term's
settings file and line): ``require_coordinate``, ``require_state_coordinate``,
``require_load``, ``require_tracked_load``, ``require_marker``, ``require_body``,
``require_control``, ``require_muscle``, ``require_tracked_activation``,
``require_parameter``.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import casadi as cs
import numpy as np

from nmsm.core import reductions
from nmsm.core.ocp import DiscontinuousDerivativeWarning, evaluation_of
from nmsm.core.row_map import map_rows
from nmsm.tools.treatment.orientation import check_sequence

if TYPE_CHECKING:
    from nmsm.core.term import ConstraintTerm, CostTerm
    from nmsm.tools.treatment.quantities import ContextQuantities
    from nmsm.core.ocp_model import TreatmentModel


class GridView:
    """Quantities on one grid of the transcribed phase (see module docstring)."""

    def __init__(self, quantities: ContextQuantities, grid: str) -> None:
        self._q = quantities
        self.grid = grid

    # ---- time -------------------------------------------------------------------------
    @property
    def n(self) -> int:
        return self._q.trajectory.grid_size(self.grid)

    @property
    def normalized_time(self) -> np.ndarray:
        return self._q.trajectory.normalized_times(self.grid)

    def time(self) -> cs.MX:
        return self._q.trajectory.times(self.grid)

    @property
    def is_integration_grid(self) -> bool:
        """True on the grid of the cost integrals (the collocation points)."""
        return self.grid == self._q.trajectory.integration_grid

    # ---- kinematics -----------------------------------------------------------------------
    def positions(self) -> cs.MX:
        return self._q.kinematics(self.grid)[0]

    def speeds(self) -> cs.MX:
        return self._q.kinematics(self.grid)[1]

    def accelerations(self) -> cs.MX:
        return self._q.kinematics(self.grid)[2]

    def coordinate(self, name: str) -> cs.MX:
        return self.positions()[:, self._q.coordinate_index(name)]

    def speed(self, name: str) -> cs.MX:
        return self.speeds()[:, self._q.coordinate_index(name)]

    def acceleration(self, name: str) -> cs.MX:
        return self.accelerations()[:, self._q.coordinate_index(name)]

    def tracked_coordinate(self, name: str) -> cs.MX:
        return self._q.tracked_kinematics(self.grid, 0)[:, self._q.coordinate_index(name)]

    def tracked_speed(self, name: str) -> cs.MX:
        return self._q.tracked_kinematics(self.grid, 1)[:, self._q.coordinate_index(name)]

    def tracked_acceleration(self, name: str) -> cs.MX:
        return self._q.tracked_kinematics(self.grid, 2)[:, self._q.coordinate_index(name)]

    # ---- kinetics ------------------------------------------------------------------------
    def inverse_dynamics(self) -> cs.MX:
        return self._q.inverse_dynamics(self.grid)

    def inverse_dynamics_load(self, load: str) -> cs.MX:
        return self.inverse_dynamics()[:, self._q.load_index(load)]

    def tracked_load(self, load: str) -> cs.MX:
        return self._q.tracked_loads(self.grid, load)

    def controller_load(self, load: str) -> cs.MX:
        coordinate = self._q.load_coordinate(load)

        def compute() -> cs.MX:
            total: cs.MX | None = None
            for controller in self._q.data.controllers:
                loads = self._q.cache((self.grid, "controller_loads", id(controller)),
                                      lambda c=controller: c.applied_loads(self))
                if coordinate in loads:
                    total = loads[coordinate] if total is None else total + loads[coordinate]
            return cs.MX(self.n, 1) if total is None else total
        return self._q.cache((self.grid, "controller_load", coordinate), compute)

    def load_coordinate(self, load: str) -> str:
        """The coordinate of an ID load label (``knee_angle_r_moment`` -> ``knee_angle_r``)."""
        return self._q.load_coordinate(load)

    # ---- points and bodies ------------------------------------------------------------------
    def marker_position(self, marker: str) -> cs.MX:
        return self._q.marker(self.grid, marker)[0]

    def marker_velocity(self, marker: str) -> cs.MX:
        return self._q.marker(self.grid, marker)[1]

    def tracked_marker_position(self, marker: str) -> cs.MX:
        return self._q.tracked_marker(self.grid, marker)[0]

    def tracked_marker_velocity(self, marker: str) -> cs.MX:
        return self._q.tracked_marker(self.grid, marker)[1]

    def body_orientation(self, body: str, sequence: str = "xyz") -> cs.MX:
        return self._q.orientation(self.grid, body, check_sequence(sequence))

    def tracked_body_orientation(self, body: str, sequence: str = "xyz") -> cs.MX:
        return self._q.tracked_orientation(self.grid, body, check_sequence(sequence))

    # ---- ground contact -----------------------------------------------------------------------
    def ground_reaction_force(self, label: str) -> cs.MX:
        """(n, 1) modeled ground reaction component named by a force column (N)."""
        contact, kind, axis = self._q.find_reaction(label)
        return self._q.ground_reaction(self.grid, contact)[0][:, axis]

    def ground_reaction_moment(self, label: str) -> cs.MX:
        """(n, 1) modeled moment component (N·m) about the contact model's reference point."""
        contact, kind, axis = self._q.find_reaction(label)
        return self._q.ground_reaction(self.grid, contact)[1][:, axis]

    def tracked_ground_reaction_force(self, label: str) -> cs.DM:
        contact, kind, axis = self._q.find_reaction(label)
        return self._q.tracked_reaction(self.grid, contact)[0][:, axis]

    def tracked_ground_reaction_moment(self, label: str) -> cs.DM:
        contact, kind, axis = self._q.find_reaction(label)
        return self._q.tracked_reaction(self.grid, contact)[1][:, axis]

    # ---- controls and muscles ------------------------------------------------------------
    def control(self, name: str) -> cs.MX:
        return self._q.control(self.grid, name)

    def controller_state(self, name: str) -> cs.MX:
        """(n, 1) a controller's own state (e.g. ``activation:<muscle>`` under activation
        dynamics) by internal name."""
        return self._q.controller_state(self.grid, name)

    def initial_control(self, name: str) -> cs.MX:
        return self._q.initial_control(self.grid, name)

    def muscle_activations(self) -> cs.MX:
        """(n, M) activations of :attr:`TreatmentContext.muscle_names`: the sum of what the
        controllers driving each muscle give it (zero for a muscle no controller drives)."""
        def compute() -> cs.MX:
            parts = []
            for controller in self._q.data.controllers:
                names = controller.muscle_names()
                if names:
                    parts.append((names, controller.muscle_activations(self)))
            cols = []
            for muscle in self._q.muscle_names:
                col = None
                for names, acts in parts:
                    if muscle in names:
                        part = acts[:, list(names).index(muscle)]
                        col = part if col is None else col + part
                cols.append(col if col is not None else cs.MX(self.n, 1))
            return cs.horzcat(*cols) if cols else cs.MX(self.n, 0)
        return self._q.cache((self.grid, "muscle_activations"), compute)

    def muscle_activation(self, muscle: str) -> cs.MX:
        return self.muscle_activations()[:, self._q.muscle_index(muscle)]

    def tracked_muscle_activation(self, muscle: str) -> cs.MX:
        return self._q.tracked_activation(self.grid, muscle)

    def normalized_fiber_length(self, muscle: str) -> cs.MX:
        return self._muscle_quantity("normalized_fiber_length")[:, self._q.muscle_index(muscle)]

    def _muscle_quantity(self, name: str) -> cs.MX:
        """(n, M) Hill-model quantity ``name`` of :attr:`TreatmentContext.muscle_names`, from the
        first controller that gives it for a muscle (zero where none does)."""
        def compute() -> cs.MX:
            cols = {}
            for controller in self._q.data.controllers:
                values = controller.muscle_quantity(self, name)
                if values is not None:
                    for j, m in enumerate(controller.muscle_names()):
                        cols.setdefault(m, values[:, j])
            names = self._q.muscle_names
            return cs.horzcat(*[cols.get(m, cs.MX(self.n, 1)) for m in names]) if names else cs.MX(self.n, 0)
        return self._q.cache((self.grid, "muscle_quantity", name), compute)

    def map_kinematics_function(self, key: Any, function: cs.Function, uses: str = "q, qd, qdd",
                                coordinates: Any = None, extra: tuple = ()) -> list[cs.MX]:
        """Evaluate a per-point SX ``function(q, qd, qdd subset..., *extra)`` on this grid,
        composed with the kinematics so its derivatives only span the decision variables
        (faster than mapping over :meth:`positions` columns). ``extra``: (n, k) or (1, k)."""
        composed = self._q.composed(key, function, uses, coordinates)
        return self._q.map_point(composed, self.grid, *extra)

    # ---- generic caching for extensions -------------------------------------------------------
    def cached(self, key: str, compute: Callable[[GridView], cs.MX]) -> cs.MX:
        """``compute(self)`` once per grid and ``key`` (for quantities added by plugins)."""
        return self._q.cache((self.grid, "plugin", key), lambda: compute(self))

    def lifted(self, key: str, compute: Callable[[GridView], cs.MX], lower: float = -np.inf,
               upper: float = np.inf) -> cs.MX:
        """``compute(self)`` (an (n, m) expression) replaced by an (n, m) block of new
        design variables ``lifted:<key>@<grid>``, equal to it by an equality constraint
        block of the same name and starting at its value at the initial guess; ``lower``,
        ``upper``: bounds the expression itself keeps (so the variables keep them too).

        The problem is the same; what changes is its derivatives' structure: a quantity
        that couples variables shared by every row (e.g. synergy vectors) with each row's
        variables becomes an input of the row's own functions, so the Hessian of the
        Lagrangian keeps one block per row instead of dense rows and columns.
        """
        def make() -> cs.MX:
            expression = cs.MX(compute(self))
            problem = self._q.trajectory.problem
            name = f"lifted:{key}@{self.grid}"
            lo, hi = problem.bounds_scaled()
            start = problem.evaluate(expression, np.clip(problem.initial_scaled(), lo, hi))
            variable = problem.variable(name, np.clip(start, lower, upper), lower, upper, shape=expression.shape,
                                        scale=np.ones(expression.shape))
            problem.add_constraint(name, variable - expression, 0.0, 0.0)
            return variable
        return self._q.cache((self.grid, "lifted", key), make)

    # ---- whole body, per-foot ground reactions, centre of pressure, metabolic rate -------------
    # (the DO goals' quantities: terms in nmsm/terms/treatment/angular_momentum.py,
    # walking_speed.py, metabolic_cost.py, impulse.py, center_of_pressure.py; computations in
    # nmsm/tools/treatment/whole_body.py and metabolics.py)
    def _whole_body(self) -> list[cs.MX]:
        from nmsm.tools.treatment.whole_body import whole_body_function

        def compute(view: GridView) -> list[cs.MX]:
            f = self._q.cache(("whole_body_function",), lambda: whole_body_function(self._q.data.model))
            return view.map_kinematics_function("whole_body", f, "q, qd", extra=tuple(self._q.model_parameter_row()))
        return self.cached("whole_body", compute)

    def center_of_mass_position(self) -> cs.MX:
        """(n, 3) whole-body centre of mass in ground (m)."""
        return self._whole_body()[0]

    def center_of_mass_velocity(self) -> cs.MX:
        """(n, 3) velocity of the centre of mass in ground (m/s)."""
        return self._whole_body()[1]

    def angular_momentum(self) -> cs.MX:
        """(n, 3) whole-body angular momentum about the centre of mass, ground axes (kg·m²/s)."""
        return self._whole_body()[2]

    def body_mass(self) -> float:
        """Total mass of the model's bodies (kg)."""
        from nmsm.tools.treatment.whole_body import total_mass

        return self._q.cache(("body_mass",), lambda: total_mass(self._q.data.model))

    def foot_contacts(self, hindfoot_body: str) -> list[Any]:
        """Contact models whose loads act on ``hindfoot_body`` first (an elastic-foundation
        surface of that hindfoot, or the smooth spheres on that body)."""
        return [c for c in self._q.data.contact_models if c.hindfoot_body == hindfoot_body]

    def foot_ground_reaction(self, hindfoot_body: str) -> tuple[cs.MX, cs.MX, cs.MX]:
        """Summed over :meth:`foot_contacts`: force (n, 3) N, moment about the ground origin
        (n, 3) N·m (elastic foundation: its own moment about its floor point, GCP's convention;
        other contact models: from the loads applied to the bodies) and the first contact's
        reference point projected on the floor (n, 3) m (y = 0), all in ground."""
        def compute(view: GridView) -> tuple[cs.MX, cs.MX, cs.MX]:
            force = moment = point = None
            from nmsm.tools.treatment.whole_body import foot_reaction_function

            for contact in self.foot_contacts(hindfoot_body):
                g = foot_reaction_function(self._q.contact_function(contact), contact.name,
                                           moment_about_floor_point=contact.moment_about_floor_point)
                F, M, P = view.map_kinematics_function(("foot_reaction", id(contact)), g, "q, qd", None,
                                                       (contact.parameters(),))
                force = F if force is None else force + F
                moment = M if moment is None else moment + M
                point = P if point is None else point
            if force is None:
                raise KeyError(f"no contact model acts on hindfoot body '{hindfoot_body}'")
            return force, moment, point
        return self.cached(("foot_ground_reaction", hindfoot_body), compute)

    def center_of_pressure(self, hindfoot_body: str) -> cs.MX:
        """(n, 3) modeled centre of pressure of a foot on the floor (m; y = 0): about the
        reference point P, ``x = P_x + M_z/F̂_y``, ``z = P_z - M_x/F̂_y``,
        ``F̂_y = F_y + sign(F_y)`` (sign(0) = 1), as the original."""
        def compute(view: GridView) -> cs.MX:
            F, M_origin, P = view.foot_ground_reaction(hindfoot_body)
            M = M_origin - _cross_rows(P, F)
            return _cop(P, F, M)
        return self.cached(("center_of_pressure", hindfoot_body), compute)

    def tracked_center_of_pressure(self, hindfoot_body: str) -> cs.DM:
        """(n, 3) experimental centre of pressure (m; y = 0) from the tracked GRF columns of
        the foot's contact surfaces: about the first surface's electrical centre ``EC``,
        ``x = EC_x + M_z/F̂_y``, ``z = EC_z - M_x/F̂_y`` (torques act at each EC)."""
        def compute(view: GridView) -> cs.DM:
            refs = self._q.data.references["ground_reactions"]
            t = self._q.reference_times(view.grid)
            seen: set[tuple[str, ...]] = set()
            F = M_origin = EC = None
            for contact in self.foot_contacts(hindfoot_body):
                labels = tuple(contact.force_labels) + tuple(contact.moment_labels) + tuple(contact.point_labels)
                if labels in seen:
                    continue
                seen.add(labels)
                f = refs.values(t, 0, contact.force_labels)
                torque = refs.values(t, 0, contact.moment_labels)
                centre = refs.values(t, 0, contact.point_labels)
                m = np.cross(centre, f) + torque
                F = f if F is None else F + f
                M_origin = m if M_origin is None else M_origin + m
                EC = centre if EC is None else EC
            M = M_origin - np.cross(EC, F)
            return cs.DM(_cop(EC, F, M))
        return self.cached(("tracked_center_of_pressure", hindfoot_body), compute)

    def belt_speed(self) -> Any:
        """Mean treadmill belt speed (m/s) of the contact surfaces that have one (0 if none);
        an MX when a model function (``applyBeltSpeedParameter``) made it a parameter."""
        speeds = (c.belt_speed() for c in self._q.data.contact_models)
        values = [v for v in speeds if v is not None]
        if not values:
            return 0.0
        return sum((cs.MX(v) for v in values), cs.MX(0)) / len(values)

    def metabolic_rate(self) -> cs.MX:
        """(n, 1) whole-body metabolic rate Ė (W): smoothed Bhargava model of every muscle of
        the muscle/synergy controllers plus the basal rate (:mod:`~nmsm.tools.treatment.metabolics`)."""
        from nmsm.tools.treatment.metabolics import BASAL_RATE, metabolic_point_function

        def compute(view: GridView) -> cs.MX:
            names = self._q.muscle_names
            params = self._q.cache(("metabolic_parameters",), self._metabolic_parameter_row)
            f = self._q.cache(("metabolic_function",), lambda: metabolic_point_function(len(names)))
            (rate,) = map_rows(f, view.muscle_activations(), view._muscle_quantity("normalized_fiber_length"),
                               view._muscle_quantity("normalized_fiber_velocity"), params,
                               parallel=self._q.parallel)
            return rate + BASAL_RATE * self.body_mass()
        return self.cached("metabolic_rate", compute)

    def _metabolic_parameter_row(self) -> cs.MX:
        """(1, 4 M) [F0, l_o, cos α, vmax] of :attr:`muscle_names` (MX: modifiers may set them)."""
        found: dict[str, tuple[Any, Any, float, float]] = {}
        for controller in self._q.data.controllers:
            model = getattr(controller, "muscle_model", None)
            if model is None:
                continue
            for j, m in enumerate(model.muscles):
                if m not in found:
                    values = model.parameters[m]
                    found[m] = (values["max_isometric_force"], values["optimal_fiber_length"],
                                float(np.cos(model.pennation[j])), float(model.vmax_factor))
        missing = [m for m in self._q.muscle_names if m not in found]
        if missing:
            raise KeyError(f"muscles without Hill parameters: {', '.join(missing)}")
        rows = [found[m] for m in self._q.muscle_names]
        return cs.horzcat(*[cs.MX(r[k]) for k in range(4) for r in rows])

    def initial_guess_value(self, expression: Any) -> np.ndarray:
        """Numeric value of an expression of the decision variables at the initial guess."""
        problem = self._q.trajectory.problem
        return problem.evaluate(expression, problem.initial_scaled())

    def require_hindfoot_body(self, term: Any, body: str, *, tracked: bool = False,
                              element: str = "<hindfoot_body_list>") -> None:
        """``body`` must carry a contact model (and, with ``tracked``, its GRF columns)."""
        contacts = self.foot_contacts(body)
        if not contacts:
            have = sorted({getattr(getattr(c, "surface", None), "hindfoot_body", None) or c.load_bodies[0]
                           for c in self._q.data.contact_models if c.load_bodies})
            raise term.error(f"no contact model acts on hindfoot body '{body}'", element=element,
                             expected="one of " + (", ".join(have) or "(no contact model: add contact surfaces to "
                                                   "the .osimx or contact forces to the model)"))
        if tracked:
            refs = self._q.data.references.get("ground_reactions")
            for c in contacts:
                for label in (*c.force_labels, *c.moment_labels, *c.point_labels):
                    if refs is None or not refs.has(label):
                        raise term.error(f"no column '{label}' in the tracked ground reactions (GRFData) for the "
                                         f"centre of pressure of '{body}'", element=element)

    def require_whole_body(self, term: Any) -> None:
        from nmsm.tools.treatment.whole_body import supports_whole_body

        if not supports_whole_body(self._q.data.model):
            raise term.error("the model has no mass properties for whole-body quantities")

    def require_metabolic_model(self, term: Any) -> None:
        """The problem must have muscles with Hill parameters (synergy or muscle controller)."""
        if not self._q.muscle_names:
            raise term.error("a metabolic cost needs muscles: add a synergy or individual-muscle controller "
                             "(a torque-driven problem has no muscle energetics)", element="<type>")
        try:
            self._q.cache(("metabolic_parameters",), self._metabolic_parameter_row)
        except KeyError as exc:
            raise term.error(str(exc.args[0]), element="<type>") from None


class TreatmentContext(GridView):
    """What terms receive: the collocation-point view, terminal views and problem-wide data.

    Implements :class:`nmsm.core.ocp.OcpContext`, the public protocol a term is written
    against (every quantity with its units and shapes).
    """

    def __init__(self, quantities: ContextQuantities) -> None:
        super().__init__(quantities, quantities.trajectory.integration_grid)
        self.tool = quantities.data.tool
        self.initial = GridView(quantities, "initial")
        self.final = GridView(quantities, "final")

    def at(self, grid: str) -> GridView:
        """View of another grid (``nodes``, ``collocation``, ``initial``, ``final``)."""
        return GridView(self._q, grid)

    # ---- problem-wide -------------------------------------------------------------------------
    @property
    def model(self) -> TreatmentModel:
        return self._q.data.model

    @property
    def final_time(self) -> cs.MX:
        return self._q.trajectory.final_time

    @property
    def reference_duration(self) -> float:
        """Duration (s) of the tracked data the references are sampled from."""
        return self._q.data.reference_duration

    @property
    def state_coordinates(self) -> tuple[str, ...]:
        return self._q.data.state_coordinates

    def is_actuated(self, coordinate: str) -> bool:
        """True when a controller applies loads on ``coordinate``."""
        return any(coordinate in c.controlled_coordinates() for c in self._q.data.controllers)

    @property
    def controller_names(self) -> tuple[str, ...]:
        return tuple(self._q.control_lookup)

    @property
    def muscle_names(self) -> tuple[str, ...]:
        return self._q.muscle_names

    def parameter(self, name: str) -> cs.MX:
        try:
            return self._q.data.parameters[name]
        except KeyError:
            raise KeyError(f"no static parameter '{name}' (have: {', '.join(self._q.data.parameters) or 'none'})") from None

    def synergy_weights(self, group: str | None = None) -> cs.MX:
        return self._q.synergy_weights(group, initial=False)

    def initial_synergy_weights(self, group: str | None = None) -> np.ndarray:
        return self._q.synergy_weights(group, initial=True)

    def differentiate(self, values: Any) -> cs.MX:
        """Time derivative (per second) of (K, m) collocation values through each interval's
        interpolating polynomial on its collocation points (an interval with one point: 0).

        Values that depend on the controls may jump between intervals, which this derivative
        does not see: the term being built then gets a
        :class:`~nmsm.core.ocp.DiscontinuousDerivativeWarning` (when it is reduced)."""
        values = cs.MX(values)
        if self._q.depends_on_controls(values):
            self._q.jump_derivative_pending = True
        return self._q.collocation_derivative() @ values / self.final_time

    def synergy_vector(self, name: str, *, initial: bool = False) -> Any:
        """(1, M_g) synergy vector of ``<group>_<k>`` (MX; numpy when ``initial``)."""
        for controller in self._q.data.controllers:
            if name in getattr(controller, "synergy_names", ()):
                return controller.synergy_vector(name, initial=initial)
        raise KeyError(f"no synergy '{name}'")

    def integrate(self, values: Any) -> cs.MX:
        """``integral_0^1 values ds`` over normalized time of (K, m) values -> (1, m)."""
        w = cs.DM(self._q.trajectory.quadrature_weights).T
        return w @ cs.MX(values)

    # ---- reductions (called by the term bases) ------------------------------------------------
    def _range_mask(self, time_ranges: Sequence[float] | None, grid: str) -> np.ndarray:
        s = self._q.trajectory.normalized_times(grid)
        if not time_ranges:
            return np.ones(s.size, dtype=bool)
        mask = np.zeros(s.size, dtype=bool)
        for a, b in zip(time_ranges[::2], time_ranges[1::2]):
            mask |= (s >= a - 1e-12) & (s <= b + 1e-12)
        return mask

    def _warn_jump_derivative(self, term: Any) -> None:
        """Warn once per term that differentiated a quantity depending on the controls."""
        if not self._q.jump_derivative_pending:
            return
        self._q.jump_derivative_pending = False
        key = (term.type, term.source.file, term.source.line)
        if key in self._q.jump_derivative_warned:
            return
        self._q.jump_derivative_warned.add(key)
        where = f"{term.source.file}:{term.source.line}: " if term.source.file else ""
        warnings.warn(
            f"{where}term '{term.type}' ({type(term).__qualname__}) differentiates a quantity that depends on the "
            "controls (accelerations, loads, torque controls or activations), which may jump from one mesh "
            "interval to the next: ctx.differentiate does not see those jumps, so minimising or bounding this "
            "derivative can raise the true one while the solver reports success. Penalise the quantity "
            "itself or the derivative of a state (coordinate or speed); docs/plugins.md 'Derivatives of the context'",
            DiscontinuousDerivativeWarning, stacklevel=2)

    def reduce_cost(self, term: CostTerm, normalized: Any) -> Any:
        self._warn_jump_derivative(term)
        if evaluation_of(term) == "discrete":
            z = cs.MX(normalized)
            if z.numel() != 1:
                raise term.error(f"a discrete cost must be a scalar, got shape {z.shape}")
            return z
        z = cs.MX(normalized)
        if z.shape != (self.n, 1):
            raise term.error(f"a continuous cost must be a ({self.n}, 1) column on the collocation points, got {z.shape}")
        weights = self._q.trajectory.quadrature_weights * self._range_mask(getattr(term, "time_ranges", None), self.grid)
        residuals = reductions.quadrature(z, weights)
        if not getattr(term, "normalize_by_final_time", True):
            residuals = residuals * cs.sqrt(self.final_time)
        return residuals

    def reduce_constraint(self, term: ConstraintTerm, value: Any) -> tuple[Any, Any, Any]:
        self._warn_jump_derivative(term)
        v = cs.MX(value)
        if evaluation_of(term) == "terminal":
            if v.numel() != 1:
                raise term.error(f"a terminal constraint must be a scalar, got shape {v.shape}")
        else:
            if v.shape != (self.n, 1):
                raise term.error(f"a path constraint must be a ({self.n}, 1) column, got {v.shape}")
            rows = np.flatnonzero(self._range_mask(getattr(term, "time_ranges", None), self.grid))
            v = v[rows.tolist(), 0]
        lo, hi = float(term.min_error), float(term.max_error)
        span = hi - lo
        mid = 0.5 * (hi + lo)
        if span <= 0:
            return v - mid, 0.0, 0.0
        return (v - mid) / span, -0.5, 0.5

    # ---- name checks ------------------------------------------------------------------------
    def require_coordinate(self, term: Any, name: str, element: str = "<coordinate_list>") -> None:
        if name not in self._q.coordinate_position:
            raise term.error(f"coordinate '{name}' is not in the model", element=element,
                             expected="one of " + ", ".join(self._q.data.model.coordinate_names))

    def require_state_coordinate(self, term: Any, name: str, element: str = "<coordinate_list>") -> None:
        self.require_coordinate(term, name, element)
        if name not in self._q.data.state_coordinates:
            raise term.error(f"coordinate '{name}' is not in <states_coordinate_list>", element=element,
                             expected="one of " + ", ".join(self._q.data.state_coordinates))

    def require_load(self, term: Any, load: str, element: str = "<load_list>") -> None:
        try:
            self._q.load_index(load)
        except KeyError:
            labels = [self._q.data.model.load_label(c) for c in self._q.data.model.coordinate_names]
            raise term.error(f"load '{load}' is not an inverse-dynamics load of the model", element=element,
                             expected="one of " + ", ".join(labels)) from None

    def require_tracked_load(self, term: Any, load: str, element: str = "<load_list>") -> None:
        self.require_load(term, load, element)
        refs = self._q.data.references.get("loads")
        if refs is None or self._q.tracked_load_label(load) is None:
            have = ", ".join(refs.labels) if refs is not None else "no IDData file"
            raise term.error(f"load '{load}' has no column in the tracked inverse dynamics (IDData)",
                             element=element, expected=f"one of: {have}")

    def require_marker(self, term: Any, marker: str, element: str = "<marker_list>") -> None:
        if marker not in self._q.data.model.marker_names:
            raise term.error(f"marker '{marker}' is not in the model", element=element,
                             expected="one of " + ", ".join(self._q.data.model.marker_names))

    def require_body(self, term: Any, body: str, element: str = "<body_list>") -> None:
        if body not in self._q.data.model.body_names:
            raise term.error(f"body '{body}' is not in the model", element=element,
                             expected="one of " + ", ".join(self._q.data.model.body_names))

    def require_control(self, term: Any, name: str, element: str = "<controller_list>") -> None:
        if name not in self._q.control_lookup:
            raise term.error(f"'{name}' is not a control of this problem's controllers", element=element,
                             expected="one of " + ", ".join(self._q.control_lookup))

    def require_muscle(self, term: Any, muscle: str, element: str = "<muscle_list>") -> None:
        if muscle not in self._q.muscle_names:
            raise term.error(f"muscle '{muscle}' is not driven by a synergy or muscle controller", element=element,
                             expected="one of " + (", ".join(self._q.muscle_names) or "(no muscle controller)"))

    def require_tracked_activation(self, term: Any, muscle: str, element: str = "<muscle_list>") -> None:
        self.require_muscle(term, muscle, element)
        refs = self._q.data.references.get("activations")
        if refs is None or not refs.has(muscle):
            raise term.error(f"no reference activation for muscle '{muscle}' (<trial>_combinedActivations.sto "
                             "in the initial guess directory)", element=element)

    def require_synergy(self, term: Any, name: str, element: str = "<synergy_list>") -> None:
        names = [n for c in self._q.data.controllers for n in getattr(c, "synergy_names", ())]
        if name not in names:
            raise term.error(f"'{name}' is not a synergy of the synergy controller", element=element,
                             expected="one of " + (", ".join(names) or "(no synergy controller)"))

    def require_reaction(self, term: Any, label: str, kind: str, element: str) -> None:
        """``label`` must be a ``kind`` ('force' | 'moment') column of a contact model, and the
        tracked GRF file must have it when the term tracks it."""
        try:
            _, found, _ = self._q.find_reaction(label)
        except KeyError:
            labels = [x for c in self._q.data.contact_models for x in getattr(c, f"{kind}_labels")]
            raise term.error(f"'{label}' is not a {kind} column of the contact surfaces", element=element,
                             expected="one of " + (", ".join(labels) or "(no contact model: add contact surfaces "
                                                   "to the .osimx or contact forces to the model)")) from None
        if found != kind:
            raise term.error(f"'{label}' is a {found} column, not a {kind} column", element=element)

    def has_tracked_ground_reaction(self, label: str) -> bool:
        refs = self._q.data.references.get("ground_reactions")
        return refs is not None and refs.has(label)

    def require_parameter(self, term: Any, name: str, element: str = "<type>") -> None:
        if name not in self._q.data.parameters:
            raise term.error(f"static parameter '{name}' is not declared in <RCNLParameterTermSet>", element=element,
                             expected="one of " + (", ".join(self._q.data.parameters) or "(none declared)"))


def _cross_rows(a: Any, b: Any) -> Any:
    """Row-wise cross product of (n, 3) MX matrices."""
    return cs.horzcat(a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                      a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


def _cop(point: Any, force: Any, moment: Any) -> Any:
    """(n, 3) centre of pressure on y = 0 from the force and its moment about ``point``
    (as the original: ``F̂_y = F_y + sign(F_y)``, sign(0) = 1)."""
    if isinstance(force, np.ndarray):
        fy = force[:, 1] + np.where(force[:, 1] >= 0, 1.0, -1.0)
        return np.c_[point[:, 0] + moment[:, 2] / fy, np.zeros(len(fy)), point[:, 2] - moment[:, 0] / fy]
    fy = force[:, 1] + cs.if_else(force[:, 1] >= 0, 1.0, -1.0)
    return cs.horzcat(point[:, 0] + moment[:, 2] / fy, cs.MX(force.shape[0], 1), point[:, 2] - moment[:, 0] / fy)

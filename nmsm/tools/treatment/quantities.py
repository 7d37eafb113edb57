"""How the treatment context's quantities are computed: one lazily built, cached CasADi
expression per (grid, quantity), model quantities as per-point SX functions mapped over a grid's
rows (:func:`~nmsm.core.row_map.map_rows`).

Terms never use this class directly: they read it through the views of
:mod:`nmsm.tools.treatment.context` (:class:`~nmsm.tools.treatment.context.GridView`,
:class:`~nmsm.tools.treatment.context.TreatmentContext`), which document the shapes and units.
What the controllers contribute (applied loads, muscle activations, Hill-model quantities) the
views ask the controllers for, handing them themselves; this module computes the rest.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import casadi as cs
import numpy as np

from nmsm.core.function_names import function_name
from nmsm.core.row_map import map_rows
from nmsm.tools.treatment.orientation import euler_angles
from nmsm.core.transcription.base import Trajectory

if TYPE_CHECKING:
    from nmsm.tools.treatment.problem_data import TreatmentData


class ContextQuantities:
    """Lazy, cached evaluation of every quantity of the context (internal: terms use the views)."""

    def __init__(self, data: TreatmentData, trajectory: Trajectory, parallel: int = 1) -> None:
        self.data = data
        self.trajectory = trajectory
        self.parallel = parallel
        self._cache: dict[Any, Any] = {}
        model = data.model
        self.coordinate_position = {c: i for i, c in enumerate(model.coordinate_names)}
        self.load_position = {model.load_label(c): i for i, c in enumerate(model.coordinate_names)}
        # controls: user-facing name -> (controller, internal control column name)
        self.control_lookup: dict[str, tuple[Any, str]] = {}
        for controller in data.controllers:
            for spec in controller.control_specs():
                for alias in (spec.name, *spec.aliases):
                    self.control_lookup.setdefault(alias, (controller, spec.name))
        names: list[str] = []
        for controller in data.controllers:
            names.extend(m for m in controller.muscle_names() if m not in names)
        self.muscle_names = tuple(names)
        #: set by ``differentiate`` of a quantity depending on the controls, cleared when the
        #: term is reduced (which warns naming it; see GridView._warn_jump_derivative)
        self.jump_derivative_pending = False
        self.jump_derivative_warned: set[tuple[Any, ...]] = set()

    def depends_on_controls(self, values: Any) -> bool:
        """True if ``values`` (MX) depend on the control variables (the per-collocation-point
        accelerations and controller controls, free to jump between mesh intervals)."""
        name = getattr(self.trajectory, "control_var", "")
        variable = self.trajectory.problem.variables.get(name) if name else None
        return variable is not None and bool(cs.depends_on(cs.MX(values), variable.scaled_symbol))

    def cache(self, key: Any, compute: Callable[[], Any]) -> Any:
        if key not in self._cache:
            self._cache[key] = compute()
        return self._cache[key]

    # ---- model parameters (Design Optimization joint-frame model functions) ----------------------
    def _parameter_count(self) -> int:
        return int(getattr(self.data.model, "parameter_count", 0))

    def model_parameter_symbols(self) -> list[cs.SX]:
        """``[p]`` (SX, (n_p, 1)) for building point functions of a parametric model, else []."""
        n = self._parameter_count()
        return [cs.SX.sym("p_model", n)] if n else []

    def model_parameter_row(self) -> list[cs.MX]:
        """``[p]`` (MX, (1, n_p)): the model parameters' values for :meth:`map_point`, else []."""
        if not self._parameter_count():
            return []
        return [cs.reshape(self.data.model_parameter_values, 1, self._parameter_count())]

    def model_parameter_initial(self, n_rows: int) -> list[cs.DM]:
        """``[P]`` (DM, (n_p, n_rows)): the file's parameter values, for numeric evaluation of
        tracked quantities (the tracked data belong to the file's model), else []."""
        if not self._parameter_count():
            return []
        initial = cs.DM(self.data.model.parameters.initial_values).reshape((-1, 1))
        return [cs.repmat(initial, 1, n_rows)]

    # ---- indices ---------------------------------------------------------------------------
    def coordinate_index(self, name: str) -> int:
        try:
            return self.coordinate_position[name]
        except KeyError:
            raise KeyError(f"coordinate '{name}' is not in the model") from None

    def load_coordinate(self, load: str) -> str:
        if load in self.coordinate_position:
            return load
        if load in self.load_position:
            return self.data.model.coordinate_names[self.load_position[load]]
        raise KeyError(f"load '{load}' is not an inverse-dynamics load of the model")

    def load_index(self, load: str) -> int:
        return self.coordinate_position[self.load_coordinate(load)]

    def muscle_index(self, muscle: str) -> int:
        try:
            return self.muscle_names.index(muscle)
        except ValueError:
            raise KeyError(f"muscle '{muscle}' is not driven by a controller") from None

    # ---- time bases ----------------------------------------------------------------------
    def reference_times(self, grid: str) -> np.ndarray:
        """Times (s) at which references are sampled: normalized time x reference duration."""
        return self.trajectory.normalized_times(grid) * self.data.reference_duration

    def time_ratio(self) -> Any:
        """``T_ref / t_f``: derivative factor of signals following normalized time."""
        tf = self.trajectory.final_time
        if self.data.free_final_time and not self.data.rescale_prescribed_derivatives:
            return 1.0
        if not self.data.free_final_time:
            return self.data.reference_duration / float(self.data.final_time_guess)
        return self.data.reference_duration / tf

    def collocation_derivative(self) -> cs.DM:
        """(K, K) d/ds of the per-interval polynomial through the collocation values."""
        def compute() -> cs.DM:
            from nmsm.core.transcription.radau import differentiation_matrix, radau_rule

            mesh = self.trajectory.phase.mesh
            D = np.zeros((mesh.n_collocation, mesh.n_collocation))
            for i, n in enumerate(mesh.points):
                idx = mesh.interval_node_indices(i)[:-1]
                if n > 1:
                    D[np.ix_(idx, idx)] = differentiation_matrix(radau_rule(n).collocation) * (2.0 / mesh.fractions[i])
            return cs.DM(D)
        return self.cache(("collocation_derivative",), compute)

    # ---- kinematics ----------------------------------------------------------------------
    def kinematics(self, grid: str) -> tuple[cs.MX, cs.MX, cs.MX]:
        def compute() -> tuple[cs.MX, cs.MX, cs.MX]:
            q, qd, qdd = self.map_point(self._full_kinematics_function(), grid)
            return q, qd, qdd
        return self.cache((grid, "kinematics"), compute)

    def _point_inputs(self, grid: str) -> tuple[cs.MX, cs.DM, Any]:
        """Per-row inputs of point functions: ``(V (n, 3 n_s) [q_s, q̇_s, q̈_s] variables,
        C (n, 3 n_p) [q_p, q̇_p, q̈_p] prescribed values on the reference time base,
        ratio T_ref / t_f)``."""
        def compute() -> tuple[cs.MX, cs.DM, Any]:
            data = self.data
            states = self.trajectory.states(grid)
            controls = self.trajectory.controls(grid)
            n_s = len(data.state_coordinates)
            off = data.acceleration_control_offset
            V = cs.horzcat(states[:, :n_s], states[:, n_s:2 * n_s], controls[:, off:off + n_s])
            prescribed = self.prescribed_coordinates
            if prescribed:
                t = self.reference_times(grid)
                C = cs.DM(np.hstack([data.prescribed.values(t, order, prescribed) for order in range(3)]))
            else:
                C = cs.DM(self.trajectory.grid_size(grid), 0)
            return V, C, self.time_ratio()
        return self.cache((grid, "point_inputs"), compute)

    @property
    def prescribed_coordinates(self) -> tuple[str, ...]:
        return tuple(c for c in self.data.model.independent_coordinates if c not in self.data.state_coordinates)

    def _full_kinematics_function(self) -> cs.Function:
        """SX ``(v, c, ratio) -> (q, q̇, q̈)`` of all coordinates for one point."""
        def compute() -> cs.Function:
            data, model = self.data, self.data.model
            n_s = len(data.state_coordinates)
            prescribed = self.prescribed_coordinates
            n_p = len(prescribed)
            v = cs.SX.sym("v", 3 * n_s)
            c = cs.SX.sym("c", 3 * n_p)
            ratio = cs.SX.sym("ratio")
            cols: tuple[list, list, list] = ([], [], [])
            for name in model.independent_coordinates:
                if name in data.state_coordinates:
                    i = data.state_coordinates.index(name)
                    cols[0].append(v[i])
                    cols[1].append(v[n_s + i])
                    cols[2].append(v[2 * n_s + i])
                else:
                    j = prescribed.index(name)
                    cols[0].append(c[j])
                    cols[1].append(c[n_p + j] * ratio)
                    cols[2].append(c[2 * n_p + j] * ratio**2)
            qi, qdi, qddi = (cs.vertcat(*col) for col in cols)
            if tuple(model.independent_coordinates) == tuple(model.coordinate_names):
                q, qd, qdd = qi, qdi, qddi
            else:
                q, qd, qdd = model.expand_function()(qi, qdi, qddi)
            return cs.Function("full_kinematics", [v, c, ratio], [q, qd, qdd])
        return self.cache(("full_kinematics_function",), compute)

    def composed(self, key: Any, function: cs.Function, uses: str = "q, qd, qdd",
                 coordinates: Any = None) -> cs.Function:
        """``function`` of the kinematics turned into an SX point function of
        ``(v, c, ratio, *extra)`` (see :meth:`_point_inputs`), so derivatives only span the
        variables. ``uses``: which of q, qd, qdd ``function`` takes first, in that order;
        ``coordinates``: pass only these coordinates' entries (default: all); the
        function's remaining inputs become the ``extra`` inputs, passed through."""
        def compute() -> cs.Function:
            full = self._full_kinematics_function()
            v, c, ratio = (cs.SX.sym(n, full.size1_in(i)) for i, n in enumerate(("v", "c", "ratio")))
            q, qd, qdd = full(v, c, ratio)
            if coordinates is not None:
                idx = [self.coordinate_index(name) for name in coordinates]
                q, qd, qdd = (cs.vertcat(*[x[i] for i in idx]) for x in (q, qd, qdd))
            args = {"q": q, "qd": qd, "qdd": qdd}
            used = [args[k.strip()] for k in uses.split(",")]
            extra = [cs.SX.sym(function.name_in(i), function.sparsity_in(i)) for i in range(len(used), function.n_in())]
            outs = function.call(used + extra)
            return cs.Function(function_name("point", function.name()), [v, c, ratio, *extra], outs)
        return self.cache(("composed", key), compute)

    def map_point(self, function: cs.Function, grid: str, *extra: Any) -> list[cs.MX]:
        """Evaluate an SX point function of ``(v, c, ratio, *extra)`` on every row of
        ``grid``; each ``extra`` is (n, k) or (1, k) (broadcast)."""
        V, C, ratio = self._point_inputs(grid)
        return map_rows(function, V, C, cs.MX(ratio) if not isinstance(ratio, float) else cs.DM(ratio), *extra,
                        parallel=self.parallel)

    def tracked_kinematics(self, grid: str, order: int) -> cs.DM:
        def compute() -> cs.DM:
            values = self.data.tracked_full_kinematics(self.reference_times(grid))
            return cs.DM(values[order])
        return self.cache((grid, "tracked_kinematics", order), compute)

    # ---- inverse dynamics -------------------------------------------------------------------
    def inverse_dynamics(self, grid: str) -> cs.MX:
        def compute() -> cs.MX:
            contacts = self.data.contact_models
            if not contacts:
                f = self.composed("inverse_dynamics", self.data.model.inverse_dynamics_function())
                (tau,) = self.map_point(f, grid, *self.model_parameter_row())
                return tau
            f = self.composed("inverse_dynamics_contact", self._contact_inverse_dynamics_function())
            loads = [self.contact_outputs(grid, c)[0] for c in contacts]
            (tau,) = self.map_point(f, grid, *loads, *self.model_parameter_row())
            return tau
        return self.cache((grid, "inverse_dynamics"), compute)

    def contact_function(self, contact: Any) -> cs.Function:
        """The contact model's point function on this problem's model (cached)."""
        return self.cache(("contact_function", id(contact)), lambda: contact.point_function(self.data.model))

    def _contact_inverse_dynamics_function(self) -> cs.Function:
        """SX ``(q, qd, qdd, l_1, ..., l_m, *geometry) -> tau``; ``l_i`` (9 k_i) are contact
        model ``i``'s loads on its ``k_i`` bodies, each (force N, point m, torque N·m) in ground."""
        def compute() -> cs.Function:
            model = self.data.model
            contacts = self.data.contact_models
            bodies = tuple(b for c in contacts for b in c.load_bodies)
            nq = len(model.coordinate_names)
            q, qd, qdd = (cs.SX.sym(n, nq) for n in ("q", "qd", "qdd"))
            columns = [cs.SX.sym(f"loads_{c.name}", 9 * len(c.load_bodies)) for c in contacts]
            loads = cs.horzcat(*[cs.reshape(col, 9, len(c.load_bodies)) for col, c in zip(columns, contacts)])
            geometry = self.model_parameter_symbols()
            tau = model.inverse_dynamics_function(bodies)(q, qd, qdd, loads, *geometry)
            return cs.Function("inverse_dynamics_contact", [q, qd, qdd, *columns, *geometry], [tau])
        return self.cache(("contact_inverse_dynamics_function",), compute)

    def contact_outputs(self, grid: str, contact: Any) -> tuple[cs.MX, cs.MX, cs.MX, cs.MX]:
        """One contact model evaluated once on every row of ``grid``: ``(loads (n, 9 k) on its
        k load bodies, each (force N, point m, torque N·m), force (n, 3) N, moment about its
        reference point (n, 3) N·m, reference point (n, 3) m)``, all in ground. The inverse
        dynamics and the ground reaction terms share this one evaluation."""
        def compute() -> tuple[cs.MX, cs.MX, cs.MX, cs.MX]:
            f = self.contact_function(contact)
            nq = len(self.data.model.coordinate_names)
            q, qd = cs.SX.sym("q", nq), cs.SX.sym("qd", nq)
            p = cs.SX.sym("p", f.size1_in(2))
            loads, force, moment, point = f(q, qd, p)
            g = cs.Function(function_name("contact_outputs", contact.name), [q, qd, p],
                            [cs.reshape(loads, -1, 1), force, moment, point])
            composed = self.composed(("contact_outputs", id(contact)), g, "q, qd")
            loads, force, moment, point = self.map_point(composed, grid, contact.parameters())
            return loads, force, moment, point
        return self.cache((grid, "contact_outputs", id(contact)), compute)

    def ground_reaction(self, grid: str, contact: Any) -> tuple[cs.MX, cs.MX, cs.MX]:
        """(force, moment about the point, point), each (n, 3), ground, of one contact model."""
        return self.contact_outputs(grid, contact)[1:]

    def find_reaction(self, label: str) -> tuple[Any, str, int]:
        """(contact model, 'force'|'moment'|'point', axis index) of a ground reaction column."""
        for c in self.data.contact_models:
            for kind, labels in (("force", c.force_labels), ("moment", c.moment_labels), ("point", c.point_labels)):
                if label in labels:
                    return c, kind, list(labels).index(label)
        raise KeyError(f"'{label}' is not a ground reaction column of the contact models")

    def tracked_reaction(self, grid: str, contact: Any) -> tuple[cs.DM, cs.DM, cs.DM]:
        """Experimental (force, moment about the modeled reference point, electrical centre),
        each (n, 3): ``M = T + (EC - P) x F`` with ``P`` the midfoot reference on the tracked
        kinematics (the tracked GRF file's torques ``T`` act at ``EC``)."""
        def compute() -> tuple[cs.DM, cs.DM, cs.DM]:
            refs = self.data.references["ground_reactions"]
            t = self.reference_times(grid)
            force = refs.values(t, 0, contact.force_labels)
            torque = refs.values(t, 0, contact.moment_labels)
            centre = refs.values(t, 0, contact.point_labels)
            q, qd, _ = self.data.tracked_full_kinematics(t)
            f = self.contact_function(contact)
            # the reference point's x and z do not depend on the contact parameters; a
            # parametric model's parameters (last entries of p) take the file's values
            n_model = self._parameter_count()
            p = cs.DM.zeros(f.size1_in(2), q.shape[0])
            if n_model:
                p[f.size1_in(2) - n_model:, :] = self.model_parameter_initial(q.shape[0])[0]
            rows = f.map(q.shape[0])(q.T, qd.T, p)
            point = np.asarray(rows[3]).T
            reference = np.c_[point[:, 0], np.zeros(len(t)), point[:, 2]]
            moment = torque + np.cross(centre - reference, force)
            return cs.DM(force), cs.DM(moment), cs.DM(centre)
        return self.cache((grid, "tracked_reaction", id(contact)), compute)

    def tracked_load_label(self, load: str) -> str | None:
        refs = self.data.references.get("loads")
        if refs is None:
            return None
        coord = self.load_coordinate(load)
        for label in (load, self.data.model.load_label(coord), coord):
            if refs.has(label):
                return label
        return None

    def tracked_loads(self, grid: str, load: str) -> cs.DM:
        label = self.tracked_load_label(load)
        if label is None:
            raise KeyError(f"load '{load}' has no column in the tracked inverse dynamics")
        refs = self.data.references["loads"]
        return self.cache((grid, "tracked_load", label),
                          lambda: cs.DM(refs.values(self.reference_times(grid), 0, [label])))

    # ---- markers and bodies -------------------------------------------------------------------
    def _marker_functions(self, marker: str) -> cs.Function:
        def compute() -> cs.Function:
            f = self.data.model.marker_function(marker)
            nq = len(self.data.model.coordinate_names)
            q = cs.SX.sym("q", nq)
            qd = cs.SX.sym("qd", nq)
            parameters = self.model_parameter_symbols()
            p = f(q, *parameters)
            v = cs.jtimes(p, q, qd)
            return cs.Function(function_name("marker", marker), [q, qd, *parameters], [p, v])
        return self.cache(("marker_function", marker), compute)

    def marker(self, grid: str, marker: str) -> tuple[cs.MX, cs.MX]:
        def compute() -> tuple[cs.MX, cs.MX]:
            f = self.composed(("marker", marker), self._marker_functions(marker), "q, qd")
            p, v = self.map_point(f, grid, *self.model_parameter_row())
            return p, v
        return self.cache((grid, "marker", marker), compute)

    def tracked_marker(self, grid: str, marker: str) -> tuple[cs.DM, cs.DM]:
        def compute() -> tuple[cs.DM, cs.DM]:
            q, qd, _ = self.data.tracked_full_kinematics(self.reference_times(grid))
            f = self._marker_functions(marker).map(q.shape[0])
            p, v = f(cs.DM(q).T, cs.DM(qd).T, *self.model_parameter_initial(q.shape[0]))
            return cs.DM(p).T, cs.DM(v).T
        return self.cache((grid, "tracked_marker", marker), compute)

    def _orientation_function(self, body: str, sequence: str) -> cs.Function:
        def compute() -> cs.Function:
            nq = len(self.data.model.coordinate_names)
            q = cs.SX.sym("q", nq)
            parameters = self.model_parameter_symbols()
            R = self.data.model.body_rotation_function(body)(q, *parameters)
            return cs.Function(function_name("orientation", body, sequence), [q, *parameters],
                               [cs.vertcat(*euler_angles(R, sequence))])
        return self.cache(("orientation_function", body, sequence), compute)

    def orientation(self, grid: str, body: str, sequence: str) -> cs.MX:
        def compute() -> cs.MX:
            f = self.composed(("orientation", body, sequence), self._orientation_function(body, sequence), "q")
            (angles,) = self.map_point(f, grid, *self.model_parameter_row())
            return angles
        return self.cache((grid, "orientation", body, sequence), compute)

    def tracked_orientation(self, grid: str, body: str, sequence: str) -> cs.DM:
        def compute() -> cs.DM:
            q, _, _ = self.data.tracked_full_kinematics(self.reference_times(grid))
            f = self._orientation_function(body, sequence).map(q.shape[0])
            return cs.DM(f(cs.DM(q).T, *self.model_parameter_initial(q.shape[0]))).T
        return self.cache((grid, "tracked_orientation", body, sequence), compute)

    # ---- controls -----------------------------------------------------------------------------
    def _lookup(self, name: str) -> tuple[Any, str]:
        try:
            return self.control_lookup[name]
        except KeyError:
            raise KeyError(f"'{name}' is not a control (have: {', '.join(self.control_lookup)})") from None

    def control(self, grid: str, name: str) -> cs.MX:
        _, internal = self._lookup(name)
        return self.trajectory.control(internal, grid)

    def controller_state(self, grid: str, name: str) -> cs.MX:
        """(n, 1) a controller's own state by internal name (``activation:<muscle>``)."""
        return self.trajectory.state(name, grid)

    def initial_control(self, grid: str, name: str) -> cs.DM:
        controller, internal = self._lookup(name)
        return self.cache((grid, "initial_control", internal),
                          lambda: cs.DM(controller.control_reference(internal, self.reference_times(grid))))

    def tracked_activation(self, grid: str, muscle: str) -> cs.DM:
        refs = self.data.references["activations"]
        return self.cache((grid, "tracked_activation", muscle),
                          lambda: cs.DM(refs.values(self.reference_times(grid), 0, [muscle])))

    def synergy_weights(self, group: str | None, *, initial: bool) -> Any:
        for controller in self.data.controllers:
            getter = getattr(controller, "synergy_weight_matrix", None)
            if getter is not None:
                return getter(group, initial=initial)
        raise KeyError("no synergy controller in this problem")

"""Individual muscle activation controller (``<RCNLMuscleController>``): one control per muscle.

Each muscle's activation (0..1) is a control ``<muscle>`` (no activation dynamics: the
activation is the control). Used for comparisons with OpenSim Moco (muscle-driven tracking).

Settings: ``muscle_list`` (default: every muscle of the geometry), ``surrogate_model_coordinate_list``
(the coordinates that receive muscle moments), ``minimum_activation`` [0.01] (lower bound),
``maximum_shortening_velocity_multiplier`` [10 l_o/s], and

* **geometry**: with ``surrogate_model_data_directory`` the surrogate of the synergy
  controller (``surrogate_model_polynomial_degree``, ``epsilon``, ``load_surrogate_model``,
  ``save_surrogate_model``); without it the **exact path geometry** of the ``.osim``
  (:class:`nmsm.model.muscle_paths.PathMuscleGeometry`: path-point muscles without
  wrapping, e.g. the Moco 2D gait model); other coordinates are held at 0 in it, so the
  coordinate list must contain every coordinate the muscles span;
* **force model** ``muscle_force_model``: ``nmsm`` (default, the pipeline's rigid-tendon
  Hill model, :mod:`nmsm.model.hill`) or ``degroote2016`` (OpenSim's
  DeGrooteFregly2016Muscle with ``ignore_tendon_compliance``: De Groote et al. 2016
  curves, fixed-width pennation, fiber damping; :func:`degroote_tendon_force`).

**Activation dynamics** (``activation_dynamics`` true; default false): the controls are
then the muscles' excitations ``e`` (``excitation:<muscle>``, in [``minimum_activation``, 1];
a muscle's name in ``<controller_list>`` means its excitation) and each activation is a state
``a`` (``activation:<muscle>``, same bounds) with OpenSim's DeGrooteFregly2016Muscle dynamics
(:func:`degroote_activation_derivative`): time constants ``activation_time_constant`` and
``deactivation_time_constant`` (s; default: the ``.osimx``'s personalized values, else each
muscle's own in the ``.osim``, else 0.015 and 0.060 with a warning: :func:`_time_constants`)
and each muscle's ``activation_dynamics_smoothing`` (else 0.1).
Excitations are written to ``<trial>_muscleExcitations.sto``.

Initial guess and ``controller_tracking`` reference: ``<trial>_combinedActivations.sto``
when present, else 0.1; with activation dynamics the excitations' come from
``<trial>_muscleExcitations.sto`` (a previous run's), else from the activations file with a
warning, else 0.1.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import attrs
import casadi as cs
import numpy as np

from nmsm.core.plugin_bases import ControlSpec, Controller, StateSpec
from nmsm.interop.moco_trajectory import MocoColumns, muscle_activation_path, muscle_control_path
from nmsm.core.controller_setup import ControllerSetup, name_list, setting
from nmsm.model.muscle_model import MuscleModel
from nmsm.model.surrogate_fitting import load_surrogate

PREFIX = "activation:"
EXCITATION_PREFIX = "excitation:"
DEFAULT_GUESS = 0.1
#: DeGrooteFregly2016Muscle's default activation and deactivation time constants (s) and
#: ``activation_dynamics_smoothing`` (OpenSim 4.6: the steepness b of the tanh switch)
DGF_TIME_CONSTANTS = (0.015, 0.060)
DGF_SMOOTHING = 0.1
FORCE_MODELS = ("nmsm", "degroote2016")

#: DeGrooteFregly2016Muscle active force-length Gaussians (amplitude, centre, width b3 + b4 l)
DGF_ACTIVE = ((0.8150671134243542, 1.055033428970575, 0.162384573599574, 0.063303448465465),
              (0.433004984392647, 0.716775413397760, -0.029947116970696, 0.200356847296188),
              (0.1, 1.0, 0.353553390593274, 0.0))
#: force-velocity d1..d4: f_V = d1 log(d2 v + d3 + sqrt((d2 v + d3)^2 + 1)) + d4
DGF_VELOCITY = (-0.3211346127989808, -8.149, -0.374, 0.8825327733249912)
#: passive curve: k_PE, strain at one normalized force e0, minimum normalized fiber length
DGF_PASSIVE = (4.0, 0.6, 0.2)


def degroote_tendon_force(a: Any, length: Any, velocity: Any, F0: Any, lo: Any, lts: Any, alpha_opt: Any,
                          vmax: float, damping: Any) -> tuple[Any, Any, Any]:
    """Rigid-tendon DeGrooteFregly2016Muscle (OpenSim 4.x, ``ignore_tendon_compliance``):
    fiber length ``l_M = sqrt((L - l_ts)^2 + (l_o sin α_o)^2)``, ``cos α = (L - l_ts)/l_M``,
    fiber velocity ``V cos α``; ``F = F0 (a f_L f_V + f_P + damping ṽ) cos α`` (N).
    Returns (F, l̃ = l_M/l_o, ṽ = v_M/(vmax l_o)). Works on SX/MX/DM (elementwise)."""
    along = length - lts
    height = lo * cs.sin(alpha_opt)
    fiber = cs.sqrt(along**2 + height**2)
    cos_alpha = along / fiber
    l_norm = fiber / lo
    v_norm = velocity * cos_alpha / (vmax * lo)
    f_l = 0
    for b1, b2, b3, b4 in DGF_ACTIVE:
        f_l = f_l + b1 * cs.exp(-0.5 * (l_norm - b2) ** 2 / (b3 + b4 * l_norm) ** 2)
    d1, d2, d3, d4 = DGF_VELOCITY
    x = d2 * v_norm + d3
    f_v = d1 * cs.log(x + cs.sqrt(x**2 + 1)) + d4
    k, e0, lmin = DGF_PASSIVE
    offset = np.exp(k * (lmin - 1) / e0)
    f_p = (cs.exp(k * (l_norm - 1) / e0) - offset) / (np.exp(k) - offset)
    force = F0 * (a * f_l * f_v + f_p + damping * v_norm) * cos_alpha
    return force, l_norm, v_norm


def degroote_activation_derivative(excitation: Any, activation: Any, activation_time_constant: Any,
                                   deactivation_time_constant: Any, smoothing: Any = DGF_SMOOTHING) -> Any:
    """da/dt (1/s) of OpenSim 4.6's DeGrooteFregly2016Muscle (De Groote et al. 2016, eq. 1-2
    with a tanh switch): ``(e - a) [f / (τ_a (0.5 + 1.5 a)) + (1 - f) (0.5 + 1.5 a) / τ_d]``,
    ``f = (1 + tanh(b (e - a))) / 2`` with ``b`` the muscle's ``activation_dynamics_smoothing``
    (0.1 by default: a gentle blend of the two rates, checked against OpenSim); excitation
    ``e`` and activation ``a`` dimensionless, time constants in s. Elementwise on SX/MX/DM."""
    factor = 0.5 + 1.5 * activation
    switch = 0.5 + 0.5 * cs.tanh(smoothing * (excitation - activation))
    rate = switch / (activation_time_constant * factor) + (1 - switch) * factor / deactivation_time_constant
    return rate * (excitation - activation)


class PathGeometry:
    """Exact path-point geometry with the interface of a surrogate (``muscle_names``,
    ``function(coordinates, muscles)``): ``(q_c, qd_c) -> (lengths (M,), velocities (M,),
    moment arms (M, n_c))`` with the model's other coordinates at 0."""

    def __init__(self, model: Any, coordinates: Sequence[str], muscles: Sequence[str] | None = None) -> None:
        from nmsm.model.muscle_paths import PathMuscleGeometry

        self.model = model
        self.coordinates = tuple(coordinates)
        self.geometry = PathMuscleGeometry(model, muscles=muscles, coordinates=self.coordinates)
        self.muscle_names = self.geometry.muscles

    def function(self, coordinates: Sequence[str] | None = None, muscles: Sequence[str] | None = None,
                 name: str = "path_muscle_geometry") -> cs.Function:
        coords = tuple(coordinates or self.coordinates)
        chosen = list(muscles or self.muscle_names)
        full = self.geometry.function()
        n_q = len(self.model.coordinates)
        q, qd = cs.SX.sym("q", len(coords)), cs.SX.sym("qd", len(coords))
        q_full, qd_full = cs.SX.zeros(n_q, 1), cs.SX.zeros(n_q, 1)
        for j, c in enumerate(coords):
            q_full[self.model.coordinate_index(c)] = q[j]
            qd_full[self.model.coordinate_index(c)] = qd[j]
        lengths, velocities, arms = full(q_full, qd_full)
        rows = [self.muscle_names.index(m) for m in chosen]
        columns = [self.geometry.coordinates.index(c) for c in coords]
        return cs.Function(name, [q, qd], [lengths[rows], velocities[rows], arms[rows, columns]])


@attrs.define
class DeGrooteMuscleModel(MuscleModel):
    """:class:`MuscleModel` with the DeGrooteFregly2016 rigid-tendon force model."""

    damping: np.ndarray = attrs.field(factory=lambda: np.zeros(0))

    def tendon_forces(self, a: Any, lengths: Any, velocities: Any, F0: Any, lo: Any, lts: Any) -> tuple[Any, Any, Any]:
        return degroote_tendon_force(a, lengths, velocities, F0, lo, lts, cs.DM(self.pennation), self.vmax_factor,
                                     cs.DM(self.damping))


class MuscleActivationController(Controller):
    """Muscle activations as controls -> Hill forces -> joint moments."""

    type: ClassVar[str] = "individual_muscle"
    settings_element: ClassVar[str] = "RCNLMuscleController"

    def __init__(self, settings: Any, setup: ControllerSetup) -> None:
        from nmsm.model import load_model

        self.setup = setup
        coordinates = name_list(setting(settings, "surrogate_model_coordinate_list"))
        if not coordinates:
            raise setup.error("the muscle controller needs <surrogate_model_coordinate_list>",
                              element="<RCNLMuscleController>")
        force_model = str(setting(settings, "muscle_force_model", "nmsm")).lower()
        if force_model not in FORCE_MODELS:
            raise setup.error(f"unknown muscle force model '{force_model}'", element="<muscle_force_model>",
                              expected=" or ".join(FORCE_MODELS))
        model = load_model(setup.model_file)
        muscles = name_list(setting(settings, "muscle_list"))
        data_directory = setting(settings, "surrogate_model_data_directory")
        if data_directory is None:
            try:
                surrogate: Any = PathGeometry(model, coordinates, muscles or None)
            except Exception as exc:  # ModelError: wrapping muscles or bad coordinates
                raise setup.error(f"no exact muscle geometry: {exc}", element="<RCNLMuscleController>",
                                  expected="path-point muscles, or a <surrogate_model_data_directory>") from exc
        else:
            surrogate = load_surrogate(
                setup.model_file, data_directory, coordinates,
                degree=int(setting(settings, "surrogate_model_polynomial_degree", 5)),
                epsilon=float(setting(settings, "epsilon", 1e-4)),
                load=bool(setting(settings, "load_surrogate_model", False)),
                save=bool(setting(settings, "save_surrogate_model", False)) and setup.save_files,
                settings_file=setup.settings_file,
                file_name=str(setting(settings, "surrogate_model_file_name", "surrogateMuscles.mat")))
        muscles = muscles or surrogate.muscle_names
        osimx = None
        if setup.osimx is not None:
            from nmsm.io.osimx import read_osimx

            osimx = read_osimx(setup.osimx)
        self.coordinates = coordinates
        self.muscles = tuple(muscles)
        self.minimum = float(setting(settings, "minimum_activation", 0.01))
        self.force_model = force_model
        self.muscle_model = MuscleModel.build(
            self.muscles, coordinates, surrogate, model, osimx,
            float(setting(settings, "maximum_shortening_velocity_multiplier", 10.0)), where=setup.settings_file)
        if force_model == "degroote2016":
            base = self.muscle_model
            damping = np.array([float(model.muscle(m).properties.get("fiber_damping", 0.0)) for m in self.muscles])
            self.muscle_model = DeGrooteMuscleModel(base.muscles, base.coordinates, base.surrogate, base.parameters,
                                                    base.pennation, base.vmax_factor, damping=damping)
        self.activation_dynamics = bool(setting(settings, "activation_dynamics", False))
        #: (M, 3) per muscle: activation and deactivation time constants (s), smoothing
        self.activation_constants = np.array([
            [*_time_constants(settings, model, osimx, m, setup.settings_file)]
            + [float(model.muscle(m).properties.get("activation_dynamics_smoothing", DGF_SMOOTHING))]
            for m in self.muscles]).reshape(len(self.muscles), 3) if self.activation_dynamics else np.zeros((0, 3))

    @classmethod
    def from_settings(cls, settings: Any, setup: ControllerSetup) -> MuscleActivationController:
        return cls(settings, setup)

    def _values(self, splines: Mapping[str, Any], times: np.ndarray, muscle: str, *,
                excitation: bool = False) -> np.ndarray:
        """(n,) a muscle's activations (or, with ``excitation`` under activation dynamics,
        excitations) from the guess files at ``times`` (s); ``DEFAULT_GUESS`` for a muscle without a column."""
        kinds = ("muscleExcitations", "combinedActivations") if excitation else ("combinedActivations",)
        for kind in kinds:
            table = splines.get(kind)
            if table is not None and table.has(muscle):
                if kind != kinds[0]:
                    self._warn_excitations_from_activations(table)
                return table.values(times, 0, [muscle]).ravel()
        return np.full(np.size(times), DEFAULT_GUESS)

    def _warn_excitations_from_activations(self, table: Any) -> None:
        if not getattr(self, "_warned_excitations", False):
            self._warned_excitations = True
            warnings.warn(f"{self.setup.settings_file}: no <trial>_muscleExcitations.sto among the initial-guess "
                          f"files: the excitations start from (and controller_tracking tracks) the activations of "
                          f"{getattr(table, 'source', None) or 'the activations file'}", stacklevel=2)

    def control_specs(self) -> list[ControlSpec]:
        prefix = EXCITATION_PREFIX if self.activation_dynamics else PREFIX
        specs = []
        for m in self.muscles:
            guess = np.clip(self._values(self.setup.starting_splines(), self.setup.starting_times(), m,
                                         excitation=self.activation_dynamics), self.minimum, 1.0)
            specs.append(ControlSpec(prefix + m, m, self.minimum, 1.0, guess, aliases=(m,)))
        return specs

    def state_specs(self) -> list[StateSpec]:
        if not self.activation_dynamics:
            return []
        times = self.setup.starting_node_times()
        return [StateSpec(PREFIX + m, m, self.minimum, 1.0,
                          np.clip(self._values(self.setup.starting_splines(), times, m), self.minimum, 1.0))
                for m in self.muscles]

    def state_dynamics(self) -> cs.Function | None:
        if not self.activation_dynamics:
            return None
        M = len(self.muscles)
        a, e = cs.SX.sym("a", M), cs.SX.sym("e", M)
        k = cs.DM(self.activation_constants)
        return cs.Function("activation_dynamics", [a, e],
                           [degroote_activation_derivative(e, a, k[:, 0], k[:, 1], k[:, 2])])

    def controlled_coordinates(self) -> tuple[str, ...]:
        return self.coordinates

    def muscle_names(self) -> tuple[str, ...]:
        return self.muscles

    def muscle_activations(self, view: Any) -> cs.MX:
        read = view.controller_state if self.activation_dynamics else view.control
        return cs.horzcat(*[read(PREFIX + m) for m in self.muscles])

    def _outputs(self, view: Any) -> cs.MX:
        return view.cached(f"muscle_controller:{id(self)}",
                           lambda v: cs.horzcat(*self.muscle_model.evaluate(v, self.muscle_activations(v))))

    def applied_loads(self, view: Any) -> Mapping[str, Any]:
        out = self._outputs(view)
        M = len(self.muscles)
        return {c: out[:, M + j] for j, c in enumerate(self.coordinates)}

    def muscle_quantity(self, view: Any, name: str) -> cs.MX | None:
        out = self._outputs(view)
        M, nc = len(self.muscles), len(self.coordinates)
        return {"tendon_force": out[:, :M], "normalized_fiber_length": out[:, M + nc:2 * M + nc],
                "normalized_fiber_velocity": out[:, 2 * M + nc:]}.get(name)

    def control_reference(self, name: str, times: np.ndarray) -> np.ndarray:
        muscle = name
        for prefix in (PREFIX, EXCITATION_PREFIX):
            muscle = muscle[len(prefix):] if muscle.startswith(prefix) else muscle
        if muscle not in self.muscles:
            raise KeyError(f"muscle controller has no control '{name}'")
        return self._values(self.setup.initial_guess, np.asarray(times, dtype=float), muscle,
                            excitation=self.activation_dynamics).reshape(-1, 1)

    def output_tables(self, solution: Any) -> dict[str, tuple[Sequence[str], np.ndarray]]:
        if not self.activation_dynamics:
            values = np.hstack([solution.control(PREFIX + m) for m in self.muscles])
            return {f"{solution.trial_name}_combinedActivations.sto": (self.muscles, values)}
        activations = np.hstack([solution.controller_state(PREFIX + m) for m in self.muscles])
        excitations = np.hstack([solution.control(EXCITATION_PREFIX + m) for m in self.muscles])
        return {f"{solution.trial_name}_combinedActivations.sto": (self.muscles, activations),
                f"{solution.trial_name}_muscleExcitations.sto": (self.muscles, excitations)}

    def moco_columns(self, solution: Any) -> MocoColumns:
        if not self.activation_dynamics:
            return MocoColumns(controls={muscle_control_path(m): solution.control(PREFIX + m) for m in self.muscles})
        return MocoColumns(
            states={muscle_activation_path(m): solution.controller_state(PREFIX + m) for m in self.muscles},
            controls={muscle_control_path(m): solution.control(EXCITATION_PREFIX + m) for m in self.muscles})


def _time_constants(settings: Any, model: Any, osimx: Any, muscle: str, where: Any) -> tuple[float, float]:
    """A muscle's activation and deactivation time constants (s), each from the first of: the
    settings' ``<activation_time_constant>`` / ``<deactivation_time_constant>``; the ``.osimx``'s
    personalized ``activation_time_constant`` (MTP; τ_d = 4 τ_a,
    :func:`nmsm.model.hill.time_constants_from_osimx`); the muscle's own properties in the
    ``.osim``; else DeGrooteFregly2016's defaults 0.015 / 0.060 s, with a warning."""
    from nmsm.model.hill import time_constants_from_osimx

    keys = ("activation_time_constant", "deactivation_time_constant")
    personalized = getattr(getattr(osimx, "muscles", {}).get(muscle), "activation_time_constant", None)
    from_osimx = time_constants_from_osimx(personalized) if personalized is not None else (None, None)
    properties = model.muscle(muscle).properties
    out = []
    for key, osimx_value, default in zip(keys, from_osimx, DGF_TIME_CONSTANTS):
        value = setting(settings, key)
        value = osimx_value if value is None else value
        value = properties.get(key) if value is None else value
        if value is None:
            warnings.warn(f"{where}: muscle '{muscle}' has no {key} (settings, .osimx or .osim): "
                          f"{default} s (DeGrooteFregly2016's default)", stacklevel=3)
            value = default
        out.append(float(value))
    return out[0], out[1]

"""Individual muscle activation controller (``<RCNLMuscleController>``): one control per muscle.

Each muscle's activation (0..1) is a control ``<muscle>``; forces and moments come from the
surrogate geometry and the Hill model as for the synergy controller
(:mod:`nmsm.tools.treatment.muscles`). Used for comparisons with OpenSim Moco
(muscle-driven tracking). Settings: ``muscle_list`` (muscles of the model, default: every
muscle of the surrogate), the surrogate elements of the synergy controller
(``surrogate_model_coordinate_list``, ``surrogate_model_data_directory``,
``surrogate_model_polynomial_degree``, ``epsilon``, ``load_surrogate_model``,
``save_surrogate_model``), ``maximum_shortening_velocity_multiplier``, and
``minimum_activation`` [0.01] (lower bound). Initial guess and ``controller_tracking``
reference: ``<trial>_combinedActivations.sto`` when present, else 0.1.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import casadi as cs
import numpy as np

from nmsm.core.plugin_bases import ControlSpec, Controller
from nmsm.tools.treatment.controller_setup import ControllerSetup, name_list, setting
from nmsm.tools.treatment.muscles import MuscleModel, load_surrogate

PREFIX = "activation:"
DEFAULT_GUESS = 0.1


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
        surrogate = load_surrogate(
            setup.model_file, setting(settings, "surrogate_model_data_directory"), coordinates,
            degree=int(setting(settings, "surrogate_model_polynomial_degree", 5)),
            epsilon=float(setting(settings, "epsilon", 1e-4)), load=bool(setting(settings, "load_surrogate_model", False)),
            save=bool(setting(settings, "save_surrogate_model", False)), settings_file=setup.settings_file)
        muscles = name_list(setting(settings, "muscle_list")) or surrogate.muscle_names
        osimx = None
        if setup.osimx is not None:
            from nmsm.io.osimx import read_osimx

            osimx = read_osimx(setup.osimx)
        self.coordinates = coordinates
        self.muscles = tuple(muscles)
        self.minimum = float(setting(settings, "minimum_activation", 0.01))
        self.muscle_model = MuscleModel.build(
            self.muscles, coordinates, surrogate, load_model(setup.model_file), osimx,
            float(setting(settings, "maximum_shortening_velocity_multiplier", 10.0)), where=setup.settings_file)

    @classmethod
    def from_settings(cls, settings: Any, setup: ControllerSetup) -> MuscleActivationController:
        return cls(settings, setup)

    def _values(self, splines: Mapping[str, Any], times: np.ndarray, muscle: str) -> np.ndarray:
        table = splines.get("combinedActivations")
        if table is not None and table.has(muscle):
            return table.values(times, 0, [muscle]).ravel()
        return np.full(np.size(times), DEFAULT_GUESS)

    def control_specs(self) -> list[ControlSpec]:
        specs = []
        for m in self.muscles:
            guess = np.clip(self._values(self.setup.starting_splines(), self.setup.starting_times(), m), self.minimum, 1.0)
            specs.append(ControlSpec(PREFIX + m, m, self.minimum, 1.0, guess, aliases=(m,)))
        return specs

    def controlled_coordinates(self) -> tuple[str, ...]:
        return self.coordinates

    def muscle_names(self) -> tuple[str, ...]:
        return self.muscles

    def muscle_activations(self, view: Any) -> cs.MX:
        return cs.horzcat(*[view.control(PREFIX + m) for m in self.muscles])

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
        muscle = name[len(PREFIX):] if name.startswith(PREFIX) else name
        if muscle not in self.muscles:
            raise KeyError(f"muscle controller has no control '{name}'")
        return self._values(self.setup.initial_guess, np.asarray(times, dtype=float), muscle).reshape(-1, 1)

    def output_tables(self, solution: Any) -> dict[str, tuple[Sequence[str], np.ndarray]]:
        values = np.hstack([solution.control(PREFIX + m) for m in self.muscles])
        return {f"{solution.trial_name}_combinedActivations.sto": (self.muscles, values)}

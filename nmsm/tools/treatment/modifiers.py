"""What Design Optimization model modifiers may change (:class:`ModificationTarget`).

A modifier (``<model_functions>`` name, :class:`~nmsm.core.plugin_bases.ModelModifier`)
runs once, after the static parameters are declared and before the terms are built. It
replaces model quantities by CasADi expressions of the parameters, so the optimizer sees
exact derivatives through them:

``target.parameter(type)``                   MX column of a ``<RCNLParameterTerm>``
``target.parameter_term(type)``              its settings (``fields``: extra elements)
``target.muscle_parameter(muscle, name)``    current value of ``max_isometric_force``,
                                             ``optimal_fiber_length`` or ``tendon_slack_length``
``target.set_muscle_parameter(muscle, name, value)``
``target.synergy_names``                     synergy controls ``<group>_<k>``
``target.scale_synergy_activation(name, factor)``   activation used by the muscles =
                                             control × factor (the control itself is unchanged)
``target.contact_models``                    contact model plugins (belt speed etc.)
``target.set_joint_frame(joint, frame, quantity, axes, values)``   a joint's parent or child
                                             offset frame's translation (m) or X-Y-Z orientation
                                             (rad) components := values (not with
                                             muscle-driven controllers)
``target.error(message, element=...)``       InputError at the settings file
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as cs
import numpy as np

from nmsm.errors import InputError, ModelError


class ModificationTarget:
    """The problem's modifiable parts (see module docstring)."""

    def __init__(self, data: Any, settings: Any) -> None:
        self.data = data
        self.settings = settings

    # ---- parameters ----------------------------------------------------------------------------
    def parameter(self, type_name: str) -> Any:
        try:
            return self.data.parameters[type_name]
        except KeyError:
            raise self.error(f"model function needs a <RCNLParameterTerm> of type '{type_name}'",
                             element="<RCNLParameterTermSet>",
                             expected="one of " + (", ".join(self.data.parameters) or "(none declared)")) from None

    def parameter_term(self, type_name: str) -> Any:
        for term in getattr(self.settings, "parameter_terms", ()):
            if term.type == type_name:
                return term
        raise self.error(f"no <RCNLParameterTerm> of type '{type_name}'", element="<RCNLParameterTermSet>")

    def error(self, message: str, *, element: str | None = None, expected: str | None = None) -> InputError:
        return InputError(message, file=getattr(self.settings, "settings_file", None), element=element, expected=expected)

    # ---- muscles ---------------------------------------------------------------------------------
    def _muscle_models(self) -> list[Any]:
        return [c.muscle_model for c in self.data.controllers if getattr(c, "muscle_model", None) is not None]

    @property
    def muscle_names(self) -> tuple[str, ...]:
        return tuple(m for model in self._muscle_models() for m in model.muscles)

    def _model_of(self, muscle: str) -> Any:
        for model in self._muscle_models():
            if muscle in model.muscles:
                return model
        raise self.error(f"muscle '{muscle}' is not driven by a synergy or muscle controller", element="<muscle>",
                         expected="one of " + (", ".join(self.muscle_names) or "(no muscle controller)"))

    def muscle_parameter(self, muscle: str, name: str) -> Any:
        return self._model_of(muscle).parameters[muscle][name]

    def set_muscle_parameter(self, muscle: str, name: str, value: Any) -> None:
        self._model_of(muscle).set_parameter(muscle, name, value)

    # ---- synergies --------------------------------------------------------------------------------
    def _synergy_controller(self, name: str | None = None) -> Any:
        for c in self.data.controllers:
            names = getattr(c, "synergy_names", None)
            if names is not None and (name is None or name in names):
                return c
        have = [n for c in self.data.controllers for n in getattr(c, "synergy_names", ())]
        raise self.error(f"no synergy control '{name}'" if name else "no synergy controller",
                         expected="one of " + (", ".join(have) or "(no synergy controller)"))

    @property
    def synergy_names(self) -> tuple[str, ...]:
        return tuple(n for c in self.data.controllers for n in getattr(c, "synergy_names", ()))

    def scale_synergy_activation(self, name: str, factor: Any) -> None:
        controller = self._synergy_controller(name)
        controller.activation_scale[name] = controller.activation_scale[name] * factor

    # ---- contact ----------------------------------------------------------------------------------
    @property
    def contact_models(self) -> list[Any]:
        return list(getattr(self.data, "contact_models", []))

    # ---- joint frames -------------------------------------------------------------------------
    def set_joint_frame(self, joint: str, frame: str, quantity: str, axes: Sequence[int], values: Any) -> None:
        """Make components ``axes`` (0 = x, 1 = y, 2 = z) of ``joint``'s ``frame`` ('parent' or
        'child') offset ``quantity`` ('translation' m, 'orientation' rad, body-fixed X-Y-Z)
        equal to ``values`` (MX, one per axis). Every kinematic quantity of the problem
        (inverse dynamics, markers, orientations, whole-body terms, elastic-foundation contact)
        then follows the moved frame; tracked data keep the file's model."""
        from nmsm.model.parameters import ModelParameters
        from nmsm.tools.treatment.model_adapter import OsimTreatmentModel

        model = self.data.model
        if not isinstance(model, OsimTreatmentModel):
            raise self.error("joint-frame model functions need an .osim model", element="<input_model_file>")
        fixed = [c.name for c in self.data.contact_models if not c.follows_model_parameters]
        if fixed:
            raise self.error(f"contact model(s) {', '.join(fixed)} cannot follow a joint-frame model function",
                             element="<model_functions>",
                             expected="elastic-foundation contact surfaces (.osimx) or no contact model")
        if self._muscle_models():
            raise self.error("joint-frame model functions are not supported with muscle-driven controllers "
                             "(the surrogate and path muscle geometry is the file's)",
                             element="<model_functions>", expected="torque (or no) controllers only")
        if frame not in ("parent", "child") or quantity not in ("translation", "orientation"):
            raise self.error(f"joint frame '{frame}' {quantity}", element="<RCNLParameterTerm>",
                             expected="frame parent|child and quantity translation|orientation")
        if not isinstance(values, cs.MX):
            values = cs.MX(cs.DM(np.atleast_1d(np.asarray(values, dtype=float))))
        values = cs.reshape(values, -1, 1)
        if values.numel() != len(axes):
            raise self.error(f"{values.numel()} values for {len(axes)} axes of joint '{joint}'",
                             element="<initial_values>", expected=f"{len(axes)} values")
        parameters = model.parameters if model.parameter_count else ModelParameters(model.model)
        register = parameters.joint_frame_translation if quantity == "translation" else parameters.joint_frame_orientation
        try:
            register(joint, frame, components=tuple(axes))
        except (ModelError, KeyError) as exc:
            raise self.error(str(exc), element="<joint>", expected="a joint of the model with a "
                             f"{frame} offset frame") from None
        except ValueError as exc:  # the same components twice
            raise self.error(str(exc), element="<model_functions>") from None
        previous = self.data.model_parameter_values
        self.data.model_parameter_values = values if previous is None else cs.vertcat(previous, values)
        self.data.model = OsimTreatmentModel(model.model, parameters)
        for contact in self.data.contact_models:
            contact.bind_model_parameters(cs.reshape(self.data.model_parameter_values, 1, parameters.size))

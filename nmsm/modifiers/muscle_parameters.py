"""Built-in muscle-parameter model functions (DO ``<model_functions>``).

Each reads the ``<RCNLParameterTerm>`` of its parameter type; the muscles come from the
term's ``<muscle>`` or ``<muscle_list>`` element (space-separated); ``initial_values`` etc.
give one value per muscle or one value shared by all listed muscles.

``applyMaxIsometricForceParameter``    type ``max_isometric_force``: F0 := value (N)
``applyOptimalFiberLengthParameter``   type ``optimal_fiber_length``: l_o := value (m)
``applyTendonSlackLengthParameter``    type ``tendon_slack_length``: l_ts := value (m)
``scaleMaxIsometricForce``             type ``max_isometric_force_scale``: F0 := F0 × value
                                       (a muscle's strength, e.g. weakness after stroke)

(The original's built-in ``apply*Parameter`` functions read the wrong field and cannot run
as model functions; these do what they intend.)
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from nmsm.core.plugin_bases import ModelModifier


def parameter_muscles(target: Any, parameter_type: str) -> tuple[Any, list[str], Any]:
    """(term settings, muscles, MX values) of the parameter term ``parameter_type``."""
    term = target.parameter_term(parameter_type)
    fields = getattr(term, "fields", {}) or {}
    text = fields.get("muscle_list") or fields.get("muscle") or ""
    muscles = text.split()
    if not muscles:
        raise target.error(f"<RCNLParameterTerm> '{parameter_type}' names no muscle", element="<muscle_list>",
                           expected="a <muscle> or <muscle_list> element")
    values = target.parameter(parameter_type)
    if values.numel() not in (1, len(muscles)):
        raise target.error(f"<RCNLParameterTerm> '{parameter_type}' has {values.numel()} values for "
                           f"{len(muscles)} muscles", element="<initial_values>", expected=f"1 or {len(muscles)} values")
    return term, muscles, values


class _SetMuscleParameter(ModelModifier):
    parameter_type: ClassVar[str] = ""
    muscle_parameter: ClassVar[str] = ""
    multiply: ClassVar[bool] = False

    def apply(self, target: Any, parameters: Mapping[str, Any]) -> None:
        _, muscles, values = parameter_muscles(target, self.parameter_type)
        for i, muscle in enumerate(muscles):
            value = values[i if values.numel() > 1 else 0]
            if self.multiply:
                value = target.muscle_parameter(muscle, self.muscle_parameter) * value
            target.set_muscle_parameter(muscle, self.muscle_parameter, value)


class ApplyMaxIsometricForceParameter(_SetMuscleParameter):
    """Sets listed muscles' max isometric force (N) to the ``max_isometric_force`` parameter."""

    type: ClassVar[str] = "applyMaxIsometricForceParameter"
    parameter_type: ClassVar[str] = "max_isometric_force"
    muscle_parameter: ClassVar[str] = "max_isometric_force"


class ApplyOptimalFiberLengthParameter(_SetMuscleParameter):
    """Sets listed muscles' optimal fiber length (m) to the ``optimal_fiber_length`` parameter."""

    type: ClassVar[str] = "applyOptimalFiberLengthParameter"
    parameter_type: ClassVar[str] = "optimal_fiber_length"
    muscle_parameter: ClassVar[str] = "optimal_fiber_length"


class ApplyTendonSlackLengthParameter(_SetMuscleParameter):
    """Sets listed muscles' tendon slack length (m) to the ``tendon_slack_length`` parameter."""

    type: ClassVar[str] = "applyTendonSlackLengthParameter"
    parameter_type: ClassVar[str] = "tendon_slack_length"
    muscle_parameter: ClassVar[str] = "tendon_slack_length"


class ScaleMaxIsometricForce(_SetMuscleParameter):
    """Scales listed muscles' max isometric force by the ``max_isometric_force_scale`` parameter."""

    type: ClassVar[str] = "scaleMaxIsometricForce"
    parameter_type: ClassVar[str] = "max_isometric_force_scale"
    muscle_parameter: ClassVar[str] = "max_isometric_force"
    multiply: ClassVar[bool] = True

"""``scaleSynergyActivation``: one synergy's activation scaled by a static parameter.

Parameter term type ``paretic_synergy_scale``: one value; ``<synergy>`` names the synergy
control (``<group>_<k>``). The muscles receive ``control x value``. With the parameter
bounded (e.g. [0.5, 1]) Design Optimization finds how much drive the synergy needs.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from nmsm.core.plugin_bases import ModelModifier

PARAMETER_TYPE = "paretic_synergy_scale"


class ScaleSynergyActivation(ModelModifier):
    """Scales one synergy's activation by the ``paretic_synergy_scale`` parameter."""

    type: ClassVar[str] = "scaleSynergyActivation"

    def apply(self, target: Any, parameters: Mapping[str, Any]) -> None:
        term = target.parameter_term(PARAMETER_TYPE)
        name = (getattr(term, "fields", {}) or {}).get("synergy", "").strip()
        if not name:
            raise target.error(f"<RCNLParameterTerm> '{PARAMETER_TYPE}' needs a <synergy> element",
                               element="<synergy>", expected="a synergy control name <group>_<k>")
        value = target.parameter(PARAMETER_TYPE)
        if value.numel() != 1:
            raise target.error(f"'{PARAMETER_TYPE}' needs one value, got {value.numel()}", element="<initial_values>")
        target.scale_synergy_activation(name, value)

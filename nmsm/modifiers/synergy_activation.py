"""``scaleSynergyActivations`` (DO ``<model_functions>``): scale synergy activations.

Parameter term type ``synergy_activation_scale`` with ``<synergy_list>`` (or ``<synergy>``)
naming synergy controls ``<group>_<k>``; one value per synergy or one shared value. The
muscles receive ``control × value`` (the control variable itself is unchanged), e.g. to
model reduced drive of a paretic side's synergies.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from nmsm.core.plugin_bases import ModelModifier

PARAMETER_TYPE = "synergy_activation_scale"


class ScaleSynergyActivations(ModelModifier):
    """Multiplies listed synergy activations by the ``synergy_activation_scale`` parameter."""

    type: ClassVar[str] = "scaleSynergyActivations"

    def apply(self, target: Any, parameters: Mapping[str, Any]) -> None:
        term = target.parameter_term(PARAMETER_TYPE)
        fields = getattr(term, "fields", {}) or {}
        names = (fields.get("synergy_list") or fields.get("synergy") or "").split()
        if not names:
            raise target.error(f"<RCNLParameterTerm> '{PARAMETER_TYPE}' names no synergy", element="<synergy_list>",
                               expected="synergy names <group>_<k>")
        values = target.parameter(PARAMETER_TYPE)
        if values.numel() not in (1, len(names)):
            raise target.error(f"{values.numel()} values for {len(names)} synergies", element="<initial_values>",
                               expected=f"1 or {len(names)} values")
        for i, name in enumerate(names):
            target.scale_synergy_activation(name, values[i if values.numel() > 1 else 0])

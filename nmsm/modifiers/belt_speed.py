"""``applyBeltSpeedParameter`` (DO ``<model_functions>``): treadmill belt speed as a parameter.

Parameter term type ``belt_speed`` (m/s), one value; ``<is_left_foot>`` (true/false) picks the
contact surfaces of that foot (absent: every surface). The elastic-foundation contact models'
friction uses the parameter as belt speed (docs/gcp.md), e.g. to find the speed a patient
walks best at.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from nmsm.core.plugin_bases import ModelModifier

PARAMETER_TYPE = "belt_speed"


class ApplyBeltSpeedParameter(ModelModifier):
    """Sets the contact surfaces' belt speed to the ``belt_speed`` parameter (m/s)."""

    type: ClassVar[str] = "applyBeltSpeedParameter"

    def apply(self, target: Any, parameters: Mapping[str, Any]) -> None:
        term = target.parameter_term(PARAMETER_TYPE)
        side = (getattr(term, "fields", {}) or {}).get("is_left_foot", "").strip().lower()
        value = target.parameter(PARAMETER_TYPE)
        if value.numel() != 1:
            raise target.error(f"'{PARAMETER_TYPE}' needs one value, got {value.numel()}", element="<initial_values>")
        surfaces = [c for c in target.contact_models if c.belt_speed() is not None
                    and (side not in ("true", "false") or c.is_left_foot == (side == "true"))]
        if not surfaces:
            raise target.error("no elastic-foundation contact surface for the belt speed (contact surfaces come "
                               "from the .osimx of Ground Contact Personalization)", element="<model_functions>")
        for contact in surfaces:
            contact.set_belt_speed(value)

"""Joint-frame model functions (DO ``<model_functions>``): move or turn a joint's frame.

``applyJointFrameTranslationParameter``   every ``<RCNLParameterTerm>`` whose type starts
                                          with ``joint_frame_translation`` (e.g.
                                          ``joint_frame_translation_elbow``): the translation
                                          (m) of ``<joint>``'s ``<frame>`` (parent | child)
                                          offset frame along ``<axes>`` (e.g. ``x z``) :=
                                          the term's values, one per axis
``applyJointFrameOrientationParameter``   the same for types starting with
                                          ``joint_frame_orientation``: body-fixed X-Y-Z
                                          orientation angles (rad)

Example: optimize where the elbow sits on the humerus (x and y in its parent frame)::

    <RCNLParameterTerm>
      <type>joint_frame_translation_elbow</type>
      <joint>r_elbow</joint> <frame>parent</frame> <axes>x y</axes>
      <initial_values>0.0061 -0.2904</initial_values>
      <lower_bounds>0.0 -0.30</lower_bounds> <upper_bounds>0.02 -0.28</upper_bounds>
    </RCNLParameterTerm>
    <model_functions>applyJointFrameTranslationParameter</model_functions>

Inverse dynamics, markers, body orientations, whole-body quantities and elastic-foundation
contact follow the moved frame with exact derivatives
(:meth:`~nmsm.tools.treatment.modifiers.ModificationTarget.set_joint_frame`); tracked data keep
the file's model. Not with muscle-driven controllers (their muscle geometry is the file's).
Values are absolute; the solved model is written as ``<model>DesignOpt.osim``. The original
has no such built-in (its Design Optimization's model parameters are muscle and belt-speed
parameters).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from nmsm.core.plugin_bases import ModelModifier

_AXES = {"x": 0, "y": 1, "z": 2}


def _frame_terms(target: Any, prefix: str) -> list[Any]:
    terms = [t for t in getattr(target.settings, "parameter_terms", ()) if t.type.startswith(prefix)]
    if not terms:
        raise target.error(f"no <RCNLParameterTerm> whose type starts with '{prefix}'",
                           element="<RCNLParameterTermSet>", expected=f"e.g. <type>{prefix}_knee</type>")
    return terms


def _field(target: Any, term: Any, name: str, expected: str) -> str:
    value = ((getattr(term, "fields", {}) or {}).get(name) or "").strip()
    if not value:
        raise target.error(f"<RCNLParameterTerm> '{term.type}' has no <{name}>", element=f"<{name}>", expected=expected)
    return value


class _ApplyJointFrame(ModelModifier):
    prefix: ClassVar[str] = ""
    quantity: ClassVar[str] = ""

    def apply(self, target: Any, parameters: Mapping[str, Any]) -> None:
        for term in _frame_terms(target, self.prefix):
            joint = _field(target, term, "joint", "a joint name of the model")
            frame = _field(target, term, "frame", "parent or child").lower()
            names = _field(target, term, "axes", "one or more of x y z").lower().split()
            if any(n not in _AXES for n in names) or len(set(names)) != len(names):
                raise target.error(f"<axes>{' '.join(names)}</axes> of '{term.type}'", element="<axes>",
                                   expected="distinct axes among x y z")
            target.set_joint_frame(joint, frame, self.quantity, [_AXES[n] for n in names], target.parameter(term.type))


class ApplyJointFrameTranslationParameter(_ApplyJointFrame):
    """Moves a joint's parent or child frame: translation (m) components := parameter values."""

    type: ClassVar[str] = "applyJointFrameTranslationParameter"
    prefix: ClassVar[str] = "joint_frame_translation"
    quantity: ClassVar[str] = "translation"


class ApplyJointFrameOrientationParameter(_ApplyJointFrame):
    """Turns a joint's parent or child frame: X-Y-Z orientation (rad) components := parameter values."""

    type: ClassVar[str] = "applyJointFrameOrientationParameter"
    prefix: ClassVar[str] = "joint_frame_orientation"
    quantity: ClassVar[str] = "orientation"

"""Base classes of the two non-term plugin kinds: controllers and model modifiers.

Their full interface is defined with Treatment Optimization (``nmsm.tools.treatment``);
here they only carry what the registry needs: a settings name (``type``) and the tools
that accept them.
"""

from __future__ import annotations

from typing import ClassVar


class Controller:
    """How a Treatment Optimization problem actuates the model (torque, synergy, ...).

    ``type`` is the controller's name; ``settings_element`` the XML element that selects
    it (e.g. ``RCNLTorqueController``).
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "VO", "DO"})
    settings_element: ClassVar[str] = ""


class ModelModifier:
    """A Design Optimization model function: changes the model from static parameters.

    ``type`` is the name used in ``<model_functions>``.
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})

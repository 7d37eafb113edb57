"""Hook specifications: how plugins (built-in or installed) add to nmsm.

A plugin is a module named by an entry point in the ``nmsm`` group. It implements one
or more of these hooks with :data:`hookimpl`; each hook returns a list of classes.
The built-in terms, constraints, controllers and modifiers are registered through
these very hooks (see ``[project.entry-points.nmsm]`` in nmsm's ``pyproject.toml``).

Example plugin module::

    from nmsm.hookspecs import hookimpl
    from nmsm.core.term import CostTerm

    class MyTerm(CostTerm):
        type = "my_term"
        tools = frozenset({"DO"})
        ...

    @hookimpl
    def nmsm_cost_terms():
        return [MyTerm]
"""

from __future__ import annotations

import pluggy

PROJECT_NAME = "nmsm"
ENTRY_POINT_GROUP = "nmsm"

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
hookimpl = pluggy.HookimplMarker(PROJECT_NAME)


class NmsmHookSpecs:
    """The hooks a plugin may implement; each returns a list of classes."""

    @hookspec
    def nmsm_cost_terms(self) -> list[type]:
        """Return :class:`nmsm.core.term.CostTerm` subclasses (settings ``<RCNLCostTerm><type>``)."""

    @hookspec
    def nmsm_constraint_terms(self) -> list[type]:
        """Return :class:`nmsm.core.term.ConstraintTerm` subclasses (``<RCNLConstraintTerm><type>``)."""

    @hookspec
    def nmsm_controllers(self) -> list[type]:
        """Return :class:`nmsm.core.plugin_bases.Controller` subclasses (torque, synergy, ...)."""

    @hookspec
    def nmsm_contact_models(self) -> list[type]:
        """Return :class:`nmsm.core.plugin_bases.ContactModel` subclasses (ground contact in TO/VO/DO)."""

    @hookspec
    def nmsm_model_modifiers(self) -> list[type]:
        """Return :class:`nmsm.core.plugin_bases.ModelModifier` subclasses (Design Optimization ``model_functions``)."""

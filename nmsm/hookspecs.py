"""Hook specifications: how plugins (built-in or installed) add to nmsm.

A plugin is a module named by an entry point in the ``nmsm`` group. It implements one
or more of these hooks with :data:`hookimpl`; each hook returns a list of classes.
The built-in terms, constraints, controllers, modifiers and back ends are registered through
these very hooks (see ``[project.entry-points.nmsm]`` in nmsm's ``pyproject.toml``, the same
as :data:`BUILTIN_PLUGINS`).

Example plugin module::

    from typing import ClassVar

    import attrs

    from nmsm.hookspecs import hookimpl
    from nmsm.core.term import CostTerm

    @attrs.frozen(kw_only=True)
    class MyTerm(CostTerm):
        type: ClassVar[str] = "my_term"
        tools: ClassVar[frozenset[str]] = frozenset({"DO"})
        ...

    @hookimpl
    def nmsm_cost_terms():
        return [MyTerm]

The registry (:mod:`nmsm.core.registry`) checks what each hook returns when it is built: a
list (not a single class) of subclasses of the hook's base, each with a ``type`` and
``tools``; term classes decorated with ``@attrs.frozen(kw_only=True)``, ``type``/``tools``
``ClassVar`` s, fields of types the settings reader reads. A function decorated with
:data:`hookimpl` whose name is not one of these hooks (``nmsm_cost_term``) is an error too.
"""

from __future__ import annotations

import pluggy

PROJECT_NAME = "nmsm"
ENTRY_POINT_GROUP = "nmsm"

#: nmsm's own plugin modules, by entry-point name (``[project.entry-points.nmsm]`` of pyproject.toml)
BUILTIN_PLUGINS: dict[str, str] = {
    "builtin_terms": "nmsm.terms",
    "builtin_constraints": "nmsm.constraints",
    "builtin_controllers": "nmsm.controllers",
    "builtin_modifiers": "nmsm.modifiers",
    "builtin_backends": "nmsm.core.backends.builtin",
}

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
hookimpl = pluggy.HookimplMarker(PROJECT_NAME)


class NmsmHookSpecs:
    """The hooks a plugin may implement; each returns a list of classes (empty, or None, if none)."""

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

    @hookspec
    def nmsm_backends(self) -> list[type]:
        """Return :class:`nmsm.core.backends.Backend` subclasses (solvers chosen by name:
        ``problem.solve("name")``)."""

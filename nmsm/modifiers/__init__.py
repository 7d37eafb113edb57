"""Built-in modifiers (one module per modifier or family), registered via the ``nmsm`` entry point.

Adding a module with a ``ModelModifier`` subclass (with a non-empty ``type``) here is all
it takes to register it.
"""

from __future__ import annotations

from nmsm.core.plugin_bases import ModelModifier
from nmsm.core.registry import classes_in_package
from nmsm.hookspecs import hookimpl


@hookimpl
def nmsm_model_modifiers() -> list[type]:
    return classes_in_package(__name__, ModelModifier)

"""Built-in controllers (one module per controller or family), registered via the ``nmsm`` entry point.

Adding a module with a ``Controller`` subclass (with a non-empty ``type``) here is all
it takes to register it.
"""

from __future__ import annotations

from nmsm.core.plugin_bases import ContactModel, Controller
from nmsm.core.registry import classes_in_package
from nmsm.hookspecs import hookimpl


@hookimpl
def nmsm_controllers() -> list[type]:
    return classes_in_package(__name__, Controller)


@hookimpl
def nmsm_contact_models() -> list[type]:
    return classes_in_package(__name__ + ".contact", ContactModel)

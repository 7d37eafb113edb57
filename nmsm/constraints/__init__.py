"""Built-in constraints (one module per constraint or family), registered via the ``nmsm`` entry point.

Adding a module with a ``ConstraintTerm`` subclass (with a non-empty ``type``) here is all
it takes to register it.
"""

from __future__ import annotations

from nmsm.core.term import ConstraintTerm
from nmsm.core.registry import classes_in_package
from nmsm.hookspecs import hookimpl


@hookimpl
def nmsm_constraint_terms() -> list[type]:
    return classes_in_package(__name__, ConstraintTerm)

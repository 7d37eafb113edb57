"""Defaults a treatment settings file leaves to the parser, reported once per term.

The original's term catalog makes ``<max_allowable_error>``
optional with default 1, so a cost term without it is not an error; but it sets the term's
weight (``((g - c)/e)^2``), so a term that omits it is reported, as an empty element is
(:meth:`nmsm.core.term.Term.from_spec`).
"""

from __future__ import annotations

from collections.abc import Iterable

import attrs

from nmsm.core.registry import get_registry
from nmsm.core.term import TermSpec, parse_bool
from nmsm.errors import RegistryError


def default_error_warnings(specs: Iterable[TermSpec], tool: str) -> list[str]:
    """One message per enabled cost term without a ``<max_allowable_error>`` element: file,
    line, term type and the default used. Unknown types are left to the term registry."""
    registry = get_registry()
    out = []
    for spec in specs:
        if spec.kind != "cost":
            continue
        try:
            if not parse_bool(spec.fields.get("is_enabled", "false")):
                continue
            cls = registry.get(spec.kind, spec.type, tool)
        except (RegistryError, ValueError):
            continue  # reported when the terms are built
        field = attrs.fields_dict(cls).get("max_allowable_error")
        if field is None or not isinstance(field.default, (int, float)):
            continue  # no such field, or a required one (the term reports it)
        if any(cls.aliases.get(element, element) == "max_allowable_error" for element in spec.fields):
            continue
        out.append(f"{spec.source.file}:{spec.source.line}: no <max_allowable_error> in term '{spec.type}' "
                   f"(default {field.default:g} used)")
    return out

"""Settings plumbing shared by the ``user_defined`` cost and constraint terms.

Every child element that is not a field of the term (e.g. ``marker_name``,
``target_speed``) is kept, as text, in ``term.options`` for the user function.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import attrs

from nmsm.core.term import Term, TermSpec


def split_options(cls: type[Term], spec: TermSpec) -> tuple[TermSpec, dict[str, str]]:
    """The spec restricted to ``cls``'s fields, and the other elements as options."""
    fields = cls.xml_fields()
    known, options = {}, {}
    for element, text in spec.fields.items():
        target = cls.aliases.get(element, element)
        if element == "type" or target in fields:
            known[element] = text
        else:
            options[element] = text
    return attrs.evolve(spec, fields=known), options


def from_spec_with_options(cls: type[Term], spec: TermSpec) -> list[Term]:
    restricted, options = split_options(cls, spec)
    return [attrs.evolve(term, options=dict(options)) for term in Term.from_spec.__func__(cls, restricted)]


def frozen_options(value: Mapping[str, str] | None) -> dict[str, str]:
    return dict(value or {})


def options_field() -> Any:
    return attrs.field(factory=dict, converter=frozen_options, eq=False)

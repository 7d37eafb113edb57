"""A cost or constraint term as a settings file declares it, before it is matched to a
registered class (:func:`nmsm.core.registry.build_terms`)."""

from __future__ import annotations

from collections.abc import Mapping

import attrs


@attrs.frozen
class SourceRef:
    """Where a term was declared: settings file and line."""

    file: str | None = None
    line: int | None = None


@attrs.frozen
class TermSpec:
    """A term as read from settings XML, before it is matched to a registered class.

    ``fields`` maps each child element name to its text (stripped); ``type`` and
    ``is_enabled`` are kept in ``fields`` too.
    """

    kind: str  # "cost" or "constraint"
    type: str
    fields: Mapping[str, str]
    source: SourceRef = SourceRef()
    field_lines: Mapping[str, int] = attrs.field(factory=dict)

"""Declarative settings classes: one attrs field per XML element.

A settings class is an ``attrs.frozen(kw_only=True)`` class whose fields are declared with
:func:`setting` (element name, kind, parser default, one-line description). The same
metadata drives reading (:func:`read_block`), unknown-element warnings and the
``nmsm print-xml`` templates (:mod:`nmsm.io.settings.template`), so they cannot drift.

Kinds: ``text``, ``number``, ``integer``, ``boolean``, ``names`` (space list),
``numbers`` / ``booleans`` (space lists, optional fixed ``count``), ``path``, ``attribute``
(an XML attribute of the block's element), ``block`` (one nested settings class),
``blocks`` (``container/element`` items, optionally only enabled ones, sorted by
``index``), ``terms`` (``RCNLCostTermSet`` or ``RCNLConstraintTermSet`` as
:class:`~nmsm.core.term.TermSpec` tuples), and, filled from the document rather than XML,
``settings_file``, ``source`` (file and line of the block) and ``tool`` (the tool element's
tag); ``fields`` keeps every child element's text (open-ended blocks such as DO parameter
terms).

A class may define ``validate(cls, values, ctx)`` (checks across fields, before
construction) and ``OTHER_ELEMENTS`` (elements known but not read: no warning).
"""

from __future__ import annotations

import difflib
import warnings
from collections.abc import Callable, Mapping
from typing import Any

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.settings.document import TERM_SETS, SettingsDocument, elements

KINDS = (
    "text",
    "number",
    "integer",
    "boolean",
    "names",
    "numbers",
    "booleans",
    "path",
    "attribute",
    "block",
    "blocks",
    "terms",
    "settings_file",
    "source",
    "fields",
    "tool",
)
_SCALAR = ("text", "number", "integer", "boolean", "names", "numbers", "booleans", "path")


@attrs.frozen
class Setting:
    """How one field is read from XML and shown in templates."""

    element: str
    kind: str
    doc: str
    required: bool = False  #: element present and non-empty
    required_element: bool = False  #: element present (may be empty)
    default: Any = None  #: parser default (``None``: absent stays ``None``)
    example: str | None = None  #: template text when there is no default
    choices: tuple[str, ...] | None = None
    count: int | None = None
    path_kind: str = "any"
    output: bool = False
    base: str | None = None  #: name of an earlier field whose path is the base folder
    exists_if: str | None = None  #: name of an earlier boolean field; the path must exist only when it is true
    empty_is_base: bool = False
    nested: type | None = None
    container: str | None = None
    sort_by_index: bool = False
    enabled_only: bool = False
    term_kind: str | None = None
    aliases: tuple[str, ...] = ()
    check: Callable[[Any], str | None] | None = None
    tool_fallback: bool = False  #: absent in the block: read it from the tool element (original's DFS)
    template: str = "show"  #: "show", "comment" (commented-out block) or "hide"
    examples: tuple[Mapping[str, str], ...] = ()  #: template terms / items


def setting(element: str = "", *, kind: str, doc: str, default: Any = attrs.NOTHING, **options: Any) -> Any:
    """An attrs field read from ``element`` (see :class:`Setting`).

    A field without ``default`` is required by Python too; its parser default for
    documentation is ``options['default_doc']`` if given.
    """
    if kind not in KINDS:
        raise ValueError(f"unknown setting kind '{kind}'")
    parser_default = None if default is attrs.NOTHING else default
    if isinstance(parser_default, attrs.Factory):  # type: ignore[arg-type]
        parser_default = parser_default.factory()
    spec = Setting(element=element, kind=kind, doc=doc, default=parser_default, **options)
    if default is attrs.NOTHING:
        return attrs.field(metadata={"nmsm": spec})
    return attrs.field(default=default, metadata={"nmsm": spec})


def settings_fields(cls: type) -> list[tuple[attrs.Attribute, Setting]]:
    """``(attribute, Setting)`` for every declared field of a settings class, in order."""
    return [(a, a.metadata["nmsm"]) for a in attrs.fields(cls) if "nmsm" in a.metadata]


@attrs.define
class ReadContext:
    """The element being read, for error messages from ``validate`` hooks."""

    doc: SettingsDocument
    element: etree._Element

    def child(self, name: str) -> etree._Element | None:
        return self.doc.child(self.element, name)

    def error(self, name: str, message: str, expected: str | None = None) -> InputError:
        """An error located at child ``name`` if present, else at this element."""
        child = self.child(name) if name else None
        return self.doc.error(
            child if child is not None else self.element,
            message,
            element=f"<{name}>" if name else None,
            expected=expected,
        )


# ----- reading ----------------------------------------------------------------------------
def _scalar(doc: SettingsDocument, parent: etree._Element, spec: Setting, element: str, values: dict[str, Any]) -> Any:
    required = spec.required
    if spec.kind == "text":
        return doc.text(parent, element, spec.default, required=required)
    if spec.kind == "number":
        return doc.number(parent, element, spec.default, required=required)
    if spec.kind == "integer":
        return doc.integer(parent, element, spec.default, required=required)
    if spec.kind == "boolean":
        return doc.boolean(parent, element, spec.default, required=required)
    if spec.kind == "names":
        names = doc.names(parent, element, spec.default if spec.default is not None else (), required=required)
        repeated = sorted({n for n in names if names.count(n) > 1}, key=names.index)
        if repeated:  # a trial or coordinate listed twice would count twice (or stop the run with a traceback)
            raise doc.error(doc.child(parent, element), f"{', '.join(repr(n) for n in repeated)} listed more than once",
                            element=f"<{element}>", expected=f"each name once in <{element}>")
        return names
    if spec.kind == "numbers":
        return doc.numbers(parent, element, spec.default, required=required, count=spec.count)
    if spec.kind == "booleans":
        return doc.booleans(parent, element, spec.default, required=required, count=spec.count)
    if spec.kind == "path":
        base = values.get(spec.base) if spec.base else None
        if spec.base and base is None:
            base = doc.path.resolve().parent
        return doc.resolved_path(
            parent,
            element,
            required=required,
            kind=spec.path_kind,
            output=spec.output,
            base=base,
            empty_is_base=spec.empty_is_base,
            must_exist=bool(values.get(spec.exists_if, True)) if spec.exists_if else True,
        )
    raise AssertionError(spec.kind)


def _element_name(doc: SettingsDocument, parent: etree._Element, spec: Setting) -> str:
    """The element actually present: the current name, else the first alias found."""
    if doc.child(parent, spec.element) is None:
        for alias in spec.aliases:
            if doc.child(parent, alias) is not None:
                return alias
    return spec.element


def _read_blocks(doc: SettingsDocument, parent: etree._Element, spec: Setting) -> tuple[Any, ...]:
    container = doc.child(parent, spec.container) if spec.container else parent
    if container is None:
        if spec.required:
            raise doc.error(
                parent,
                f"required element <{spec.container}> is missing in <{parent.tag}>"
                + doc.misspelling_hint(parent, spec.container),
                element=f"<{spec.container}>",
                expected=f"<{spec.container}> with <{spec.element}> elements",
            )
        return ()
    items = doc.children(container, spec.element)
    for other in elements(container):
        if other.tag != spec.element:
            raise doc.error(
                other, f"unexpected <{other.tag}> in <{container.tag}>", expected=f"<{spec.element}> elements"
            )
    if spec.required and not items:
        raise doc.error(
            container, f"<{container.tag}> has no <{spec.element}>", expected=f"at least one <{spec.element}>"
        )
    assert spec.nested is not None
    read = [(item, read_block(spec.nested, doc, item)) for item in items]
    if spec.sort_by_index:
        read = _sorted_by_index(doc, container, spec.element, read)
    if spec.enabled_only:
        read = [(item, obj) for item, obj in read if getattr(obj, "is_enabled", True)]
    return tuple(obj for _, obj in read)


def _sorted_by_index(
    doc: SettingsDocument, container: etree._Element, tag: str, read: list[tuple[Any, Any]]
) -> list[tuple[Any, Any]]:
    if len(read) <= 1:
        return read
    for item, obj in read:
        if getattr(obj, "index", None) is None:
            raise doc.error(
                item,
                f"<{tag}> without <index> while <{container.tag}> holds {len(read)} of them",
                element="<index>",
                expected="an <index> in every task (the order tasks run in)",
            )
    seen: dict[int, Any] = {}
    for item, obj in read:
        if obj.index in seen:
            raise doc.error(
                item,
                f"index {obj.index} used twice (also at line {seen[obj.index].sourceline})",
                element="<index>",
                expected="distinct task indices",
            )
        seen[obj.index] = item
    return sorted(read, key=lambda pair: pair[1].index)


def _warn_unknown(doc: SettingsDocument, cls: type, element: etree._Element) -> None:
    known: set[str] = set(getattr(cls, "OTHER_ELEMENTS", ()))
    for _, spec in settings_fields(cls):
        if spec.kind == "fields":
            return
        if spec.kind in ("attribute", "settings_file", "source", "tool"):
            continue
        if spec.kind == "blocks" and spec.container:
            known.add(spec.container)
        elif spec.kind != "blocks":
            known.add(spec.element)
        known.update(spec.aliases)
    if any(spec.kind == "blocks" and not spec.container for _, spec in settings_fields(cls)):
        return
    for child in elements(element):
        if child.tag in known:
            continue
        close = difflib.get_close_matches(str(child.tag), sorted(known), n=1, cutoff=0.75)
        hint = f" (did you mean <{close[0]}>?)" if close else ""
        warnings.warn(
            f"{doc.path}:{child.sourceline}: unknown element <{child.tag}> in <{element.tag}> ignored{hint}",
            stacklevel=4,
        )


def _warn_nested_only(doc: SettingsDocument, element: etree._Element, name: str) -> None:
    """Warn when ``name`` is not a direct child but the original's depth-first lookup would find it."""
    for found in element.iter(name):
        if found is element:
            continue
        ancestors = {a.tag for a in found.iterancestors()}
        if ancestors & set(TERM_SETS):
            continue
        warnings.warn(
            f"{doc.path}:{found.sourceline}: <{name}> is inside <{found.getparent().tag}>, not a direct child of "
            f"<{element.tag}>; the original's depth-first lookup would use it, nmsm does not (move it up)",
            stacklevel=4,
        )
        return


def read_block(cls: type, doc: SettingsDocument, element: etree._Element) -> Any:
    """An instance of settings class ``cls`` read from ``element``."""
    values: dict[str, Any] = {}
    for attribute, spec in settings_fields(cls):
        kind = spec.kind
        if kind in _SCALAR:
            parent = element
            name = _element_name(doc, element, spec)
            if spec.tool_fallback and doc.child(element, name) is None:
                parent = doc.tool_element
                name = _element_name(doc, parent, spec)
            if spec.required_element and doc.child(parent, name) is None:
                raise doc.error(
                    parent,
                    f"required element <{spec.element}> is missing in <{parent.tag}>"
                    + doc.misspelling_hint(parent, spec.element),
                    element=f"<{spec.element}>",
                    expected=f"<{spec.element}> (it may be empty)",
                )
            if doc.child(parent, name) is None and not spec.required:
                _warn_nested_only(doc, parent, spec.element)
            value = _scalar(doc, parent, spec, name, values)
        elif kind == "attribute":
            value = element.get(spec.element)
            if value is None and spec.required:
                raise doc.error(
                    element,
                    f'<{element.tag}> has no {spec.element}="..." attribute',
                    expected=f'<{element.tag} {spec.element}="...">',
                )
            if value is None:
                value = spec.default
        elif kind == "block":
            child = doc.child(element, spec.element)
            if child is None:
                if spec.required:
                    raise doc.error(
                        element,
                        f"required element <{spec.element}> is missing in <{element.tag}>"
                        + doc.misspelling_hint(element, spec.element),
                        element=f"<{spec.element}>",
                        expected=f"<{spec.element}>",
                    )
                value = spec.default
            else:
                assert spec.nested is not None
                value = read_block(spec.nested, doc, child)
        elif kind == "blocks":
            value = _read_blocks(doc, element, spec)
        elif kind == "terms":
            if spec.required and doc.child(element, spec.element) is None:
                raise doc.error(
                    element,
                    f"required element <{spec.element}> is missing in <{element.tag}>"
                    + doc.misspelling_hint(element, spec.element),
                    element=f"<{spec.element}>",
                    expected=f"<{spec.element}> (it may be empty)",
                )
            value = tuple(doc.term_specs(element, spec.term_kind))
        elif kind == "settings_file":
            value = doc.path
        elif kind == "source":
            value = doc.source(element)
        elif kind == "tool":
            value = doc.tool
        elif kind == "fields":
            value = {str(c.tag): doc.text_of(c) for c in elements(element)}
        else:  # pragma: no cover - guarded by setting()
            raise AssertionError(kind)
        if value is not None and spec.choices and kind == "text" and value not in spec.choices:
            lowered = {c.lower(): c for c in spec.choices}
            if str(value).lower() in lowered:
                value = lowered[str(value).lower()]
            else:
                raise doc.error(
                    doc.child(element, spec.element),
                    f"'{value}' is not a valid <{spec.element}>",
                    expected="one of " + ", ".join(spec.choices),
                )
        if value is not None and spec.check is not None:
            problem = spec.check(value)
            if problem:
                where = doc.child(element, spec.element)
                raise doc.error(
                    where if where is not None else element, f"value {value!r} {problem}", element=f"<{spec.element}>"
                )
        values[attribute.name] = value
    validate = getattr(cls, "validate", None)
    if validate is not None:
        validate(values, ReadContext(doc, element))
    _warn_unknown(doc, cls, element)
    return cls(**values)


# ----- common checks ----------------------------------------------------------------------
def positive(value: Any) -> str | None:
    return None if value > 0 else "must be > 0"


def non_negative(value: Any) -> str | None:
    return None if value >= 0 else "must be >= 0"


def at_least_one(value: Any) -> str | None:
    return None if value >= 1 else "must be >= 1"


def increasing_pair(value: Any) -> str | None:
    return None if len(value) == 2 and value[0] < value[1] else "must be two numbers 'start end' with start < end"


def not_empty(value: Any) -> str | None:
    return None if len(value) else "must name at least one item"

"""A stage's settings XML as the runner handles it: read, rewired, made movable, hashed.

Every tool's settings class declares its path elements (``setting(kind="path")``, see
:mod:`nmsm.io.settings.schema`), so the runner finds them generically, nested blocks and
the synergy controller's tool-level fallback included:

* :meth:`StageSettings.set_path` points an input element at another file or folder (the
  previous stage's output);
* :meth:`StageSettings.absolutize` rewrites every remaining relative path as the absolute
  path it meant where it was written (the original settings file's folder, with nmsm's
  usual fallbacks), and fills empty "this folder" elements, so the settings keep their
  meaning once written into the results tree;
* :meth:`StageSettings.text` serializes the settings for the results tree, paths inside
  the results directory written relative to the new file (the tree can be moved);
* :meth:`StageSettings.input_digest` hashes the settings with every input path replaced by
  the content digest of what it names (:mod:`nmsm.tools.pipeline.hashing`).
"""

from __future__ import annotations

import copy
import os
import warnings
from collections.abc import Iterator
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import normalize_separators, resolve_path
from nmsm.io.settings.document import PIPELINE_VERSION_TEXT, ROOT, elements
from nmsm.io.settings.schema import Setting, settings_fields
from nmsm.io.xml_input import element_text, set_element_text
from nmsm.tools.pipeline.hashing import DigestCache, text_digest


@attrs.frozen
class PathField:
    """One path element of a settings tree.

    ``parent``: the element that holds (or would hold) it; ``element``: the element itself
    or ``None`` when absent; ``spec``: its declaration; ``base``: the resolved folder it is
    relative to (``None``: the settings file's folder); ``key``: ``/``-joined element path
    from the tool element (``JMPTaskList/JMPTask[2]/marker_file_name``).
    """

    parent: etree._Element
    element: etree._Element | None
    spec: Setting
    base: Path | None
    key: str


def _block_items(parent: etree._Element, spec: Setting) -> list[etree._Element]:
    container = parent.find(spec.container) if spec.container else parent
    if container is None:
        return []
    return [item for item in elements(container) if item.tag == spec.element]


@attrs.define
class StageSettings:
    """A tool settings tree (current schema) and the file its relative paths were written in."""

    root: etree._Element
    origin: Path
    settings_class: type

    @property
    def tool(self) -> etree._Element:
        return next(child for child in elements(self.root))

    @property
    def tool_tag(self) -> str:
        return str(self.tool.tag)

    # ---- construction --------------------------------------------------------------------
    @classmethod
    def from_file(cls, path: Path, settings_class: type, *, upgrade: bool = True) -> StageSettings:
        """Read a settings file; older schemas of the personalization and treatment tools are
        upgraded in memory (:func:`~nmsm.io.settings.reader.read_settings_document`)."""
        from nmsm.io.settings.document import parse_settings_xml
        from nmsm.io.settings.reader import read_settings_document

        if upgrade:
            root = read_settings_document(path, check_paths=False).root
        else:
            root = parse_settings_xml(path)
        return cls(copy.deepcopy(root), Path(path).resolve(), settings_class)

    @classmethod
    def from_element(cls, tool: etree._Element, origin: Path, settings_class: type) -> StageSettings:
        """Settings embedded in a pipeline file (relative paths relative to ``origin``'s folder)."""
        root = etree.Element(ROOT, Version=PIPELINE_VERSION_TEXT)
        root.append(copy.deepcopy(tool))
        return cls(root, Path(origin).resolve(), settings_class)

    # ---- path elements ---------------------------------------------------------------------
    def path_fields(self) -> Iterator[PathField]:
        """Every declared path element, in declaration order (absent ones included)."""
        yield from self._walk(self.settings_class, self.tool, self.tool.tag)

    def _walk(self, cls: type, element: etree._Element, key: str) -> Iterator[PathField]:
        resolved: dict[str, Path] = {}
        for attribute, spec in settings_fields(cls):
            if spec.kind == "path":
                parent = element
                child = _child(element, spec)
                if child is None and spec.tool_fallback:
                    fallback = _child(self.tool, spec)
                    if fallback is not None:
                        parent, child = self.tool, fallback
                base = resolved.get(spec.base) if spec.base else None
                if spec.base and base is None:
                    base = self.origin.parent
                field = PathField(parent, child, spec, base, f"{key}/{spec.element}")
                yield field
                value = self.resolve(field)
                if value is not None:
                    resolved[attribute.name] = value
            elif spec.kind == "block" and spec.nested is not None:
                child = element.find(spec.element)
                if child is not None:
                    yield from self._walk(spec.nested, child, f"{key}/{spec.element}")
            elif spec.kind == "blocks" and spec.nested is not None:
                prefix = f"{key}/{spec.container}" if spec.container else key
                for k, item in enumerate(_block_items(element, spec), start=1):
                    yield from self._walk(spec.nested, item, f"{prefix}/{spec.element}[{k}]")

    def field(self, key: str) -> PathField:
        """The path field with element path ``key`` below the tool element (``data_directory``,
        ``RCNLSynergyController/surrogate_model_data_directory``)."""
        wanted = f"{self.tool_tag}/{key}"
        for field in self.path_fields():
            if field.key == wanted:
                return field
        raise KeyError(f"<{self.tool_tag}> has no path element '{key}'")

    def has_field(self, key: str) -> bool:
        try:
            self.field(key)
        except KeyError:
            return False
        return True

    def resolve(self, field: PathField, *, must_exist: bool = False) -> Path | None:
        """The absolute path ``field`` names (``None`` when empty and not a "this folder" element).

        Relative text resolves as the tools resolve it; a path not found anywhere resolves
        to ``base / text`` unless ``must_exist`` (then the tool's own error is raised).
        """
        text = element_text(field.element)
        if not text:
            if field.spec.empty_is_base:
                return field.base if field.base is not None else self.origin.parent
            return None
        cleaned = normalize_separators(text)
        if Path(cleaned).is_absolute():
            return Path(cleaned)
        kind = field.spec.path_kind if not field.spec.output else "any"
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the tool warns about fallbacks when it reads the file
                return resolve_path(text, settings_file=self.origin, line=field.element.sourceline,
                                    element=field.spec.element, base=field.base, must_exist=True, kind=kind)
        except InputError:
            if must_exist:
                raise
            return (field.base if field.base is not None else self.origin.parent) / cleaned

    # ---- changes ---------------------------------------------------------------------------
    def set_path(self, key: str, value: Path) -> None:
        """Point path element ``key`` at ``value`` (absolute), creating the element if absent."""
        field = self.field(key)
        element = field.element
        if element is None:
            element = etree.SubElement(field.parent, field.spec.element)
        set_element_text(element, str(Path(value).resolve()))

    def set_text(self, element_name: str, text: str) -> None:
        """Set a direct child of the tool element (created if absent)."""
        element = self.tool.find(element_name)
        if element is None:
            element = etree.SubElement(self.tool, element_name)
        set_element_text(element, text)

    def absolutize(self) -> None:
        """Rewrite relative and empty "this folder" path elements as absolute paths."""
        for field in list(self.path_fields()):
            if field.spec.output:
                continue
            value = self.resolve(field)
            if value is None:
                continue
            element = field.element
            if element is None:
                element = etree.SubElement(field.parent, field.spec.element)
            element.text = str(value)

    # ---- output ----------------------------------------------------------------------------
    def text(self, settings_file: Path, results_root: Path) -> str:
        """The settings as written to ``settings_file``: paths below ``results_root`` relative
        to the file's folder, others absolute."""
        tree = copy.deepcopy(self.root)
        work = StageSettings(tree, self.origin, self.settings_class)
        folder = settings_file.resolve().parent
        root = results_root.resolve()
        changes = []  # collected first: a base element's new text must not change how others resolve
        for field in work.path_fields():
            if field.element is None or not element_text(field.element):
                continue
            value = Path(normalize_separators(element_text(field.element)))
            if not value.is_absolute() or not _is_within(value.resolve(), root):
                continue
            relative_to = field.base.resolve() if field.spec.base and field.base is not None else folder
            if field.spec.base and not _is_within(value.resolve(), relative_to):
                continue  # keep absolute: relative text would be read against the base folder
            changes.append((field.element, Path(os.path.relpath(value.resolve(), relative_to)).as_posix()))
        for element, text in changes:
            set_element_text(element, text)
        etree.indent(tree, space="  ")
        return etree.tostring(tree, pretty_print=True, xml_declaration=True, encoding="UTF-8").decode()

    def input_digest(self, cache: DigestCache, *extra: str) -> str:
        """Digest of the settings with every input path replaced by its content digest and
        output paths left out (the results folder's location does not matter)."""
        tree = copy.deepcopy(self.root)
        work = StageSettings(tree, self.origin, self.settings_class)
        for field in list(work.path_fields()):
            if field.element is None:
                continue
            if field.spec.output:
                set_element_text(field.element, "")
                continue
            value = work.resolve(field)
            set_element_text(field.element, "" if value is None else cache.path(value))
        for comment in list(tree.iter(etree.Comment)):
            parent = comment.getparent()
            if parent is not None:  # lxml's remove drops the tail: keep it, it is the value after the comment
                previous = comment.getprevious()
                if previous is not None:
                    previous.tail = (previous.tail or "") + (comment.tail or "")
                else:
                    parent.text = (parent.text or "") + (comment.tail or "")
                parent.remove(comment)
        for element in tree.iter():
            if element.text is not None and not element.text.strip():
                element.text = None
            element.tail = None
        canonical = etree.tostring(tree, method="c14n").decode()
        return text_digest(canonical, *extra)


def _child(element: etree._Element, spec: Setting) -> etree._Element | None:
    for name in (spec.element, *spec.aliases):
        found = element.find(name)
        if found is not None:
            return found
    return None


def _is_within(path: Path, folder: Path) -> bool:
    try:
        path.relative_to(folder)
    except ValueError:
        return False
    return True

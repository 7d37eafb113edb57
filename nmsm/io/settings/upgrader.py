"""The editing machinery of settings upgrades: an :class:`Upgrader` over a copy of an old
settings tree that keeps source lines and records notes (used by the legacy-schema modules
and :mod:`nmsm.io.settings.upgrade`)."""

from __future__ import annotations

import copy
from pathlib import Path

import attrs
from lxml import etree

from nmsm.io.settings.document import PIPELINE_VERSION_TEXT, ROOT, elements


@attrs.define
class UpgradeResult:
    """The upgraded root and what was changed or could not be carried over."""

    root: etree._Element
    schema: str
    notes: list[str] = attrs.field(factory=list)


class Upgrader:
    """Editing helpers that keep source lines and record notes."""

    def __init__(self, root: etree._Element, path: Path, schema: str) -> None:
        self.root = root
        self.path = path
        self.schema = schema
        self.notes: list[str] = []

    # ----- notes ------------------------------------------------------------------------
    def note(self, element: etree._Element | None, message: str) -> None:
        where = f"line {element.sourceline}: " if element is not None and element.sourceline else ""
        self.notes.append(where + message)

    # ----- edits ------------------------------------------------------------------------
    @staticmethod
    def new(tag: str, text: str | None = None, *, like: etree._Element | None = None) -> etree._Element:
        element = etree.Element(tag)
        element.text = text
        if like is not None and like.sourceline:
            element.sourceline = like.sourceline
        return element

    def rename(self, element: etree._Element, tag: str) -> etree._Element:
        element.tag = tag
        return element

    def rename_child(self, parent: etree._Element, old: str, new: str) -> etree._Element | None:
        child = child_of(parent, old)
        if child is not None:
            if child_of(parent, new) is not None:
                self.drop(child, f"both <{old}> and <{new}> are present; <{new}> kept")
                return None
            child.tag = new
        return child

    def drop(self, element: etree._Element, why: str) -> None:
        """Replace ``element`` (and the descriptive comment just before it) by a comment quoting it; note why."""
        parent = element.getparent()
        self.remove_description(element)
        copy_ = copy.deepcopy(element)
        copy_.tail = None
        for c in list(copy_.iter(etree.Comment)):
            c.getparent().remove(c)
        quoted = " ".join(etree.tostring(copy_, encoding="unicode").split()).replace("--", "- -")
        comment = etree.Comment(f" nmsm upgrade-settings: {quoted} dropped: {why} ")
        comment.tail = element.tail
        parent.replace(element, comment)
        self.note(element, f"<{element.tag}> dropped: {why}")

    @staticmethod
    def remove_description(element: etree._Element) -> None:
        """Remove the comment right before ``element`` (the old file's description of it)."""
        previous = element.getprevious()
        if previous is not None and previous.tag is etree.Comment and not (previous.text or "").startswith(" nmsm"):
            previous.getparent().remove(previous)

    def ensure(
        self, parent: etree._Element, tag: str, text: str = "", *, why: str | None = None, index: int | None = None
    ) -> etree._Element:
        found = child_of(parent, tag)
        if found is not None:
            return found
        element = self.new(tag, text, like=parent)
        if index is None:
            parent.append(element)
        else:
            parent.insert(index, element)
        if why:
            self.note(parent, f"<{tag}>{text}</{tag}> added: {why}")
        return element

    def flatten_sets(self) -> None:
        """Remove OpenSim ``<objects>`` wrappers and ``<groups>`` elements everywhere."""
        for objects in list(self.root.iter("objects")):
            parent = objects.getparent()
            position = parent.index(objects)
            for child in reversed(list(objects)):
                parent.insert(position, child)
            parent.remove(objects)
        for groups in list(self.root.iter("groups")):
            if len(list(elements(groups))):
                self.drop(groups, "OpenSim set groups have no current equivalent")
            else:
                groups.getparent().remove(groups)

    def set_root(self, tool: etree._Element) -> None:
        """Make ``<NMSMPipelineDocument Version=current>`` the root holding ``tool``."""
        root = etree.Element(ROOT, Version=PIPELINE_VERSION_TEXT)
        root.sourceline = self.root.sourceline
        root.append(tool)
        self.root = root


def child_of(parent: etree._Element, tag: str) -> etree._Element | None:
    for child in elements(parent):
        if child.tag == tag:
            return child
    return None

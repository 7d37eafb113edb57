"""Reading OpenSim XML: typed property values, component paths and socket resolution.

An OpenSim component's path joins the names of its ancestors that are components
(``/jointset/knee_r/femur_r_offset``); list properties (``<objects>``, ``<frames>``,
``<coordinates>``, ``<components>``) and a few named non-component sets add nothing.
Sockets name another component by an absolute path or a path relative to the component
that owns the socket.
"""

from __future__ import annotations

import posixpath
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np
from lxml import etree

from nmsm.errors import ModelError
from nmsm.model.functions import FUNCTION_TAGS

#: named elements that are not components (they add no segment to a path)
NON_COMPONENT_TAGS = frozenset(
    {"WrapObjectSet", "ObjectGroup", "PathPointSet", "PathWrapSet", "GeometrySet", "VisibleObject",
     "Appearance", "SurfaceProperties", "TransformAxis"}
) | FUNCTION_TAGS


class XmlReader:
    """Typed access to the properties of an ``.osim`` document, with errors naming ``file``."""

    def __init__(self, root: etree._Element, file: str | Path) -> None:
        self.root = root
        self.file = str(file)
        model = root if root.tag == "Model" else root.find("Model")
        if model is None:
            raise ModelError("no <Model> element", file=self.file, expected="an OpenSim model document")
        self.model = model

    # ------------------------------------------------------------------ elements
    def elements(self, tags: Iterable[str]) -> Iterator[etree._Element]:
        """Every element under the model whose tag is in ``tags``, in document order
        (the ``<defaults>`` block of old files, which holds templates, is skipped)."""
        wanted = set(tags)
        for elem in self.model.iter():
            if isinstance(elem.tag, str) and elem.tag in wanted and not in_defaults(elem):
                yield elem

    def describe(self, elem: etree._Element) -> str:
        name = elem.get("name")
        return f"{elem.tag} '{name}'" if name is not None else elem.tag

    def error(self, elem: etree._Element, message: str, expected: str | None = None) -> ModelError:
        return ModelError(message, file=self.file, line=elem.sourceline, element=self.describe(elem),
                          expected=expected)

    # ------------------------------------------------------------------ values
    def text(self, elem: etree._Element, tag: str, default: str | None = None) -> str | None:
        child = elem.find(tag)
        if child is None or child.text is None or not child.text.strip():
            return default
        return child.text.strip()

    def floats(self, elem: etree._Element, tag: str, default: Iterable[float] | None = None,
               size: int | None = None) -> np.ndarray:
        text = self.text(elem, tag)
        if text is None:
            if default is None:
                raise self.error(elem, f"missing <{tag}>", expected=f"<{tag}> with numbers")
            return np.asarray(list(default), dtype=float)
        try:
            values = np.array([float(v) for v in text.split()], dtype=float)
        except ValueError:
            raise self.error(elem, f"<{tag}> holds '{text}'", expected="numbers") from None
        if size is not None and values.size != size:
            raise self.error(elem, f"<{tag}> has {values.size} numbers", expected=f"{size} numbers")
        return values

    def float(self, elem: etree._Element, tag: str, default: float | None = None) -> float:
        values = self.floats(elem, tag, None if default is None else [default])
        if values.size != 1:
            raise self.error(elem, f"<{tag}> has {values.size} numbers", expected="one number")
        return float(values[0])

    def bool(self, elem: etree._Element, tag: str, default: bool) -> bool:
        text = self.text(elem, tag)
        if text is None:
            return default
        low = text.lower()
        if low in ("true", "1"):
            return True
        if low in ("false", "0"):
            return False
        raise self.error(elem, f"<{tag}> holds '{text}'", expected="true or false")

    def names(self, elem: etree._Element, tag: str) -> tuple[str, ...]:
        text = self.text(elem, tag)
        return tuple(text.split()) if text else ()


def in_defaults(elem: etree._Element) -> bool:
    """True for elements inside a ``<defaults>`` block (object templates, not components)."""
    return any(a.tag == "defaults" for a in elem.iterancestors())


def component_path(elem: etree._Element) -> str:
    """The OpenSim component path of ``elem`` (``/`` for the model itself)."""
    segments: list[str] = []
    node = elem
    while node is not None and node.tag != "Model":
        name = node.get("name")
        if name is not None and node.tag not in NON_COMPONENT_TAGS:
            segments.append(name)
        node = node.getparent()
    return "/" + "/".join(reversed(segments))


def resolve_path(reference: str, owner_path: str) -> str:
    """Absolute path of a socket ``reference`` owned by the component at ``owner_path``."""
    reference = reference.strip()
    if reference.startswith("/"):
        joined = reference
    else:
        joined = owner_path.rstrip("/") + "/" + reference
    normal = posixpath.normpath(joined)
    return "/" if normal in ("/", "//") else normal

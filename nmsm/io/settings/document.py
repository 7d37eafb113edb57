"""A parsed settings XML file: root ``NMSMPipelineDocument`` plus one tool element.

:func:`~nmsm.io.settings.reader.read_settings_document` parses with line numbers, upgrades older schemas (with a
warning; see ``docs/settings-upgrade.md``) and checks the version: major version other
than 1 is an error, another minor version a warning.

Element lookup: :meth:`SettingsDocument.child` reads a direct child (what the settings
classes use: explicit paths). :meth:`SettingsDocument.find` has the original's semantics:
the direct child if there is one, else the first match of a depth-first walk in document
order (sibling subtrees can shadow each other, so use it only where that is wanted).

Typed getters take ``(parent, name)`` and return ``default`` when the element is absent or
empty; ``required=True`` makes absence (or emptiness) an :class:`InputError` naming the
file, the parent's line and the element. Only the literal text ``true`` is true and
``false`` false; anything else is an error rather than a silent ``false``.
"""

from __future__ import annotations

import difflib
import math
import os
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import attrs
from lxml import etree

from nmsm.io.term_spec import SourceRef, TermSpec
from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.xml_input import element_text, parse_xml_file

#: the NMSM Pipeline version whose settings schema nmsm reads
PIPELINE_VERSION = (1, 5, 3)
PIPELINE_VERSION_TEXT = ".".join(map(str, PIPELINE_VERSION))
ROOT = "NMSMPipelineDocument"

#: tool element -> short code used by ``nmsm print-xml``
TOOL_ELEMENTS: dict[str, str] = {
    "JointModelPersonalizationTool": "jmp",
    "MuscleTendonPersonalizationTool": "mtp",
    "NeuralControlPersonalizationTool": "ncp",
    "GroundContactPersonalizationTool": "gcp",
    "TrackingOptimizationTool": "to",
    "VerificationOptimizationTool": "vo",
    "DesignOptimizationTool": "do",
    "OptimalControlSolverSettings": "solver",
}

#: term-set element -> (term element, TermSpec kind)
TERM_SETS: dict[str, tuple[str, str]] = {
    "RCNLCostTermSet": ("RCNLCostTerm", "cost"),
    "RCNLConstraintTermSet": ("RCNLConstraintTerm", "constraint"),
}
_MISSING = object()


def elements(parent: etree._Element) -> Iterator[etree._Element]:
    """Element children of ``parent`` (comments and processing instructions skipped)."""
    return (child for child in parent if isinstance(child.tag, str))


def parse_version(text: str | None) -> tuple[int, ...] | None:
    """``"1.5.0"`` -> ``(1, 5, 0)``; ``None`` when not dotted integers."""
    if not text:
        return None
    try:
        return tuple(int(p) for p in text.strip().split("."))
    except ValueError:
        return None


@attrs.define
class SettingsDocument:
    """A settings file: its root, its tool element, and typed, line-aware getters."""

    path: Path
    root: etree._Element
    tool_element: etree._Element
    version: str
    upgraded_from: str | None = None
    check_paths: bool = True
    _fallbacks_warned: set[str] = attrs.field(factory=set, init=False, repr=False)

    @property
    def tool(self) -> str:
        """The tool element's tag, e.g. ``JointModelPersonalizationTool``."""
        return str(self.tool_element.tag)

    # ----- locations and errors ---------------------------------------------------------
    def line(self, element: etree._Element | None) -> int | None:
        return None if element is None else element.sourceline

    def error(
        self,
        where: etree._Element | None,
        message: str,
        *,
        element: str | None = None,
        expected: str | None = None,
    ) -> InputError:
        """An :class:`InputError` at ``where``'s line; ``element`` names it (default: ``where``'s tag)."""
        name = element if element is not None else (f"<{where.tag}>" if where is not None else None)
        return InputError(message, file=self.path, line=self.line(where), element=name, expected=expected)

    def require_tool(self, tool: str) -> None:
        """An :class:`InputError` unless the tool element is ``tool``."""
        if self.tool != tool:
            raise self.error(self.tool_element, f"this is a <{self.tool}> settings file", expected=f"<{tool}>")

    def source(self, element: etree._Element) -> SourceRef:
        return SourceRef(file=str(self.path), line=self.line(element))

    # ----- lookup -----------------------------------------------------------------------
    def children(self, parent: etree._Element, name: str) -> list[etree._Element]:
        """Direct children named ``name``, in document order."""
        return [c for c in elements(parent) if c.tag == name]

    def child(self, parent: etree._Element, name: str) -> etree._Element | None:
        """The direct child ``name``; ``None`` if absent; an error if repeated."""
        found = self.children(parent, name)
        if len(found) > 1:
            raise self.error(
                found[1],
                f"<{name}> appears {len(found)} times in <{parent.tag}> (first at line {found[0].sourceline})",
                expected=f"one <{name}>",
            )
        return found[0] if found else None

    def find(self, parent: etree._Element, name: str) -> etree._Element | None:
        """The original's lookup: direct child first, else depth-first in document order."""
        direct = self.children(parent, name)
        if direct:
            return direct[0]
        for element in parent.iter(name):
            if element is not parent:
                return element
        return None

    def misspelling_hint(self, parent: etree._Element, name: str) -> str:
        """`` (found <nmae> at line N: did you mean <name>?)`` when a child of ``parent`` that is
        not ``<name>`` is spelled close to it (a required element reported missing), else ``""``."""
        others = [child for child in parent if isinstance(child.tag, str) and child.tag != name]
        close = difflib.get_close_matches(name, [child.tag for child in others], n=1, cutoff=0.75)
        if not close:
            return ""
        found = next(child for child in others if child.tag == close[0])
        return f" (found <{found.tag}> at line {found.sourceline}: did you mean <{name}>?)"

    def text_of(self, element: etree._Element | None) -> str:
        return element_text(element)

    def _present(self, parent: etree._Element, name: str, required: bool) -> etree._Element | None:
        element = self.child(parent, name)
        if element is None or self.text_of(element) == "":
            if required:
                what = "missing" if element is None else "empty"
                hint = self.misspelling_hint(parent, name) if element is None else ""
                raise self.error(
                    element if element is not None else parent,
                    f"required element <{name}> is {what} in <{parent.tag}>{hint}",
                    element=f"<{name}>",
                    expected=f"<{name}> with a value",
                )
            return None
        return element

    # ----- typed getters ----------------------------------------------------------------
    def text(self, parent: etree._Element, name: str, default: Any = None, *, required: bool = False) -> Any:
        element = self._present(parent, name, required)
        return default if element is None else self.text_of(element)

    def _converted(self, parent: etree._Element, name: str, default: Any, required: bool, convert, what: str) -> Any:
        element = self.child(parent, name)
        if element is not None and self.text_of(element) == "" and not required and default is not None:
            warnings.warn(
                f"{self.path}:{element.sourceline}: empty <{name}> treated as absent (default {default!r} used)",
                stacklevel=3,
            )
        element = self._present(parent, name, required)
        if element is None:
            return default
        text = self.text_of(element)
        try:
            return convert(text)
        except (TypeError, ValueError) as exc:
            detail = (
                f": {exc}"
                if str(exc) and "could not convert" not in str(exc) and "invalid literal" not in str(exc)
                else ""
            )
            raise self.error(element, f"'{text}' is not {what}{detail}", expected=what) from None

    def number(self, parent: etree._Element, name: str, default: Any = None, *, required: bool = False) -> Any:
        """A float (``610e3`` style accepted)."""
        return self._converted(parent, name, default, required, _to_float, "a number")

    def integer(self, parent: etree._Element, name: str, default: Any = None, *, required: bool = False) -> Any:
        """An integer (``2e3`` accepted; ``2.5`` is an error)."""
        return self._converted(parent, name, default, required, _to_int, "an integer")

    def boolean(self, parent: etree._Element, name: str, default: Any = None, *, required: bool = False) -> Any:
        """``true`` or ``false``."""
        return self._converted(parent, name, default, required, to_bool, "true or false")

    def names(self, parent: etree._Element, name: str, default: Any = (), *, required: bool = False) -> Any:
        """A space-separated list of names (tuple)."""
        element = self._present(parent, name, required)
        return default if element is None else tuple(self.text_of(element).split())

    def numbers(
        self,
        parent: etree._Element,
        name: str,
        default: Any = None,
        *,
        required: bool = False,
        count: int | None = None,
    ) -> Any:
        """A space-separated list of numbers (tuple); ``count`` checks the length."""
        return self._converted(
            parent,
            name,
            default,
            required,
            lambda t: _sized([_to_float(p) for p in t.split()], count),
            _many("numbers", count),
        )

    def booleans(
        self,
        parent: etree._Element,
        name: str,
        default: Any = None,
        *,
        required: bool = False,
        count: int | None = None,
    ) -> Any:
        """A space-separated list of ``true``/``false`` (tuple); ``count`` checks the length."""
        return self._converted(
            parent,
            name,
            default,
            required,
            lambda t: _sized([to_bool(p) for p in t.split()], count),
            _many("true/false values", count),
        )

    def resolved_path(
        self,
        parent: etree._Element,
        name: str,
        *,
        required: bool = False,
        kind: str = "any",
        output: bool = False,
        base: Path | None = None,
        empty_is_base: bool = False,
        must_exist: bool = True,
    ) -> Path | None:
        """A path written in the settings file, resolved (see :mod:`nmsm.io.paths`).

        ``output`` paths (and any path with ``must_exist=False``) need not exist.
        ``empty_is_base``: an empty (or absent) element means the settings file's folder (or
        ``base``), as the original's empty means ``pwd``.
        """
        element = self._present(parent, name, required and not empty_is_base)
        if element is None:
            if empty_is_base:
                return base if base is not None else self.path.resolve().parent
            return None
        check = self.check_paths and not output and must_exist
        return resolve_path(
            self.text_of(element),
            settings_file=self.path,
            line=element.sourceline,
            element=name,
            base=base,
            must_exist=check,
            kind=kind if check else "any",
            on_fallback=self._warn_fallback_once,
        )

    def _warn_fallback_once(self, text: str, found: Path, where: str) -> None:
        """One warning per settings file and fallback folder (the tutorial layout triggers it for every input)."""
        if where in self._fallbacks_warned:
            return
        self._fallbacks_warned.add(where)
        warnings.warn(
            f"{self.path}: '{text.strip()}' and other paths are not next to the settings file; they are resolved "
            f"relative to {where} (e.g. {found})",
            stacklevel=5,
        )

    # ----- terms ------------------------------------------------------------------------
    def term_specs(self, parent: etree._Element, kind: str | None = None) -> list[TermSpec]:
        """``RCNLCostTermSet/RCNLCostTerm`` and ``RCNLConstraintTermSet/RCNLConstraintTerm`` under ``parent``.

        ``kind`` ("cost" / "constraint") keeps one family. Fields hold every child element's
        stripped text (``type`` and ``is_enabled`` included) and the ``name`` attribute.
        """
        out: list[TermSpec] = []
        for set_tag, (term_tag, term_kind) in TERM_SETS.items():
            if kind is not None and term_kind != kind:
                continue
            term_set = self.child(parent, set_tag)  # a second set is an error: its terms would count twice
            if term_set is None:
                continue
            for term in elements(term_set):
                if term.tag != term_tag:
                    raise self.error(
                        term, f"unexpected <{term.tag}> in <{set_tag}>", expected=f"<{term_tag}> elements"
                    )
                out.append(self.term_spec(term, term_kind))
        return out

    def _check_allowable_error(self, term: etree._Element, term_type: str) -> None:
        """A ``<max_allowable_error>`` that is a number <= 0 is an error where it is written,
        also in a block that is not enabled (its terms are built only when it is used)."""
        element = term.find("max_allowable_error")
        try:
            value = float(self.text_of(element)) if element is not None else 1.0
        except ValueError:
            return  # not a number: the term reports it when it is built
        if not value > 0:
            raise self.error(element, f"term '{term_type}': 'max_allowable_error' must be > 0 (got {value})",
                             expected="a number > 0")

    def term_spec(self, term: etree._Element, kind: str) -> TermSpec:
        fields: dict[str, str] = {}
        lines: dict[str, int] = {}
        for child in elements(term):
            if child.tag in fields:
                raise self.error(
                    child, f"<{child.tag}> appears twice in one term", expected=f"one <{child.tag}> per term"
                )
            if any(isinstance(grandchild.tag, str) for grandchild in child):  # comments are allowed
                raise self.error(child, f"<{child.tag}> has child elements", expected="a term field with text only")
            fields[str(child.tag)] = self.text_of(child)
            lines[str(child.tag)] = child.sourceline
        name = term.get("name")
        if name is not None and "name" not in fields:
            fields["name"] = name
            lines["name"] = term.sourceline
        term_type = fields.get("type", "")
        if not term_type:
            raise self.error(
                term,
                f"{'missing' if 'type' not in fields else 'empty'} <type> in <{term.tag}>",
                element="<type>",
                expected="the term's type name",
            )
        self._check_allowable_error(term, term_type)
        return TermSpec(kind=kind, type=term_type, fields=fields, source=self.source(term), field_lines=lines)


# ----- conversions ------------------------------------------------------------------------
def to_bool(text: str) -> bool:
    """Only ``true`` is true and ``false`` false."""
    if text == "true":
        return True
    if text == "false":
        return False
    raise ValueError("only the literal text 'true' or 'false' is accepted")


def _to_float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):  # no setting means anything by nan or inf (float() reads both)
        raise ValueError(f"{text.strip()} is not finite")
    return value


#: the largest integer setting: iteration and evaluation counts reach the solvers as C ints
#: (IPOPT read max_iter 1e308 as 0 iterations), and an <index> becomes part of a folder name
MAX_INTEGER = 2**31 - 1


def _to_int(text: str) -> int:
    value = float(text)
    if not value.is_integer():
        raise ValueError(f"{text} is not a whole number")
    if abs(value) > MAX_INTEGER:
        raise ValueError(f"{text} is out of range (at most {MAX_INTEGER} in magnitude)")
    return int(value)


def _sized(values: Sequence[Any], count: int | None) -> tuple[Any, ...]:
    if count is not None and len(values) != count:
        raise ValueError(f"{len(values)} values given")
    return tuple(values)


def _many(what: str, count: int | None) -> str:
    return f"{count} space-separated {what}" if count else f"space-separated {what}"


# ----- reading ----------------------------------------------------------------------------
def parse_settings_xml(path: str | os.PathLike[str]) -> etree._Element:
    """The root element of ``path`` (with line numbers); malformed XML -> :class:`InputError`."""
    return parse_xml_file(path, what="settings file")


def tool_element_of(root: etree._Element, path: Path) -> etree._Element:
    """The single tool element under the root; unknown or repeated tool elements are errors."""
    found = list(elements(root))
    if len(found) != 1:
        raise InputError(
            f"<{root.tag}> holds {len(found)} elements",
            file=path,
            line=root.sourceline,
            element=f"<{root.tag}>",
            expected="exactly one tool element: " + ", ".join(f"<{t}>" for t in TOOL_ELEMENTS),
        )
    tool = found[0]
    if tool.tag not in TOOL_ELEMENTS:
        raise InputError(
            f"unknown tool element <{tool.tag}>",
            file=path,
            line=tool.sourceline,
            element=f"<{tool.tag}>",
            expected="one of " + ", ".join(f"<{t}>" for t in TOOL_ELEMENTS),
        )
    return tool


def check_version(root: etree._Element, path: Path) -> str:
    """The root's ``Version``: major must be 1 (error), minor should match (warning)."""
    text = root.get("Version")
    version = parse_version(text)
    if version is None:
        raise InputError(
            f"missing or unreadable Version attribute '{text}'",
            file=path,
            line=root.sourceline,
            element=f"<{root.tag}>",
            expected=f'Version="{PIPELINE_VERSION_TEXT}"',
        )
    if version[0] != PIPELINE_VERSION[0]:
        raise InputError(
            f"settings version {text} is not supported",
            file=path,
            line=root.sourceline,
            element=f"<{root.tag}>",
            expected=f"major version {PIPELINE_VERSION[0]} (this is NMSM Pipeline {PIPELINE_VERSION_TEXT})",
        )
    if len(version) < 2 or version[1] != PIPELINE_VERSION[1]:
        warnings.warn(
            f"{path}: settings version {text} differs from {PIPELINE_VERSION_TEXT} in the minor version; "
            "elements may have changed",
            stacklevel=3,
        )
    return str(text)


#: OpenSim tool settings (``<OpenSimDocument>``) that 'nmsm run' is given by mistake -> where they belong
OPENSIM_TOOL_FILES = {
    "InverseKinematicsTool": "an OpenSim IK settings file is read by 'nmsm ik MODEL --ik-settings FILE' "
    "and 'nmsm preprocess --ik-settings FILE'",
    "InverseDynamicsTool": "for inverse dynamics run 'nmsm id MODEL MOTION --external-loads LOADS.xml -o OUT.sto'",
    "AnalyzeTool": "for a muscle analysis run 'nmsm muscle-analysis MODEL MOTION -o MAData'",
    "ExternalLoads": "an ExternalLoads file is given to 'nmsm id' and 'nmsm preprocess' as --external-loads",
    "ScaleTool": "nmsm has no scaling tool: scale the model in OpenSim",
}


def read_tool_element(path: Path, tool: str, hint: str = "") -> etree._Element:
    """The one ``<tool>`` element of the ``<NMSMPipelineDocument>`` file ``path`` (a pipeline or
    batch file), its root and version checked; ``hint`` ends the error's expectation."""
    root = parse_settings_xml(path)
    if root.tag != ROOT:
        raise InputError(f"root element is <{root.tag}>", file=path, line=root.sourceline, element=f"<{root.tag}>",
                         expected=f"<{ROOT}> with a <{tool}> element")
    check_version(root, path)
    tools = [c for c in elements(root) if c.tag == tool]
    if len(tools) != 1:
        raise InputError(f"{len(tools)} <{tool}> elements", file=path, line=root.sourceline,
                         expected=f"exactly one <{tool}>{hint}")
    return tools[0]

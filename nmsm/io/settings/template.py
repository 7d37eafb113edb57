"""``nmsm print-xml TOOL``: a commented settings template built from the settings classes.

Every element comes from a field declared with :func:`~nmsm.io.settings.schema.setting`:
its one-line description and parser default become the comment and the value, so the
template cannot drift from the reader. Required elements without a default show an example
value; optional elements without a default are shown commented out.
"""

from __future__ import annotations

from typing import Any

from lxml import etree

from nmsm.io.settings.document import PIPELINE_VERSION_TEXT, ROOT, TERM_SETS
from nmsm.io.settings.schema import Setting, settings_fields

_NOT_XML = ("settings_file", "source", "tool", "fields")


def format_value(value: Any) -> str:
    """Settings text of a Python value (``true``/``false``, space lists, shortest floats)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (tuple, list)):
        return " ".join(format_value(v) for v in value)
    if isinstance(value, float):
        return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)
    return str(value)


def _value_text(spec: Setting) -> str | None:
    if spec.default is not None and not (isinstance(spec.default, tuple) and not spec.default and spec.example):
        return format_value(spec.default)
    return spec.example


def _clean(text: str) -> str:
    text = " ".join(text.split()).replace("--", "- -")
    return f" {text.rstrip('-')} "


def _describe(spec: Setting, value: str | None) -> str:
    parts = [spec.doc.rstrip(".")]
    if spec.choices:
        parts.append("one of " + ", ".join(spec.choices))
    if spec.required:
        parts.append("required")
    elif spec.required_element:
        parts.append("element required, may be empty")
    elif spec.default is not None and value is not None:
        parts.append(f"default {value}" if value != "" else "default: empty")
    return _clean(". ".join(parts) + ".")


def _commented_block(doc: str, nested: etree._Element) -> str:
    """A block shown commented out: one line per element, its description after it."""
    lines = [f" {doc} (optional; remove the comment marks to use it):", f"<{nested.tag}>"]
    description = ""
    for child in nested:
        if child.tag is etree.Comment:
            description = " ".join((child.text or "").split())
            if description.startswith("<"):
                lines.append(f"  ({description})")
                description = ""
            continue
        lines.append(f"  <{child.tag}>{child.text or ''}</{child.tag}>    ({description})")
        description = ""
    lines.append(f"</{nested.tag}>")
    return "\n".join(line.replace("--", "- -") for line in lines) + "\n"


def block_template(cls: type, tag: str) -> etree._Element:
    """A commented template element for settings class ``cls``."""
    element = etree.Element(tag)
    for _, spec in settings_fields(cls):
        if spec.template == "hide" or spec.kind in _NOT_XML:
            continue
        if spec.kind == "attribute":
            example = spec.example if spec.example is not None else spec.default
            if example is not None:
                element.set(spec.element, str(example))
            continue
        if spec.kind == "block":
            assert spec.nested is not None
            nested = block_template(spec.nested, spec.element)
            if spec.template == "comment":
                element.append(etree.Comment(_commented_block(spec.doc, nested)))
            else:
                element.append(etree.Comment(_describe(spec, None)))
                element.append(nested)
            continue
        if spec.kind == "blocks":
            assert spec.nested is not None
            element.append(etree.Comment(_describe(spec, None)))
            container = etree.SubElement(element, spec.container) if spec.container else element
            container.append(block_template(spec.nested, spec.element))
            continue
        if spec.kind == "terms":
            term_tag = TERM_SETS[spec.element][0]
            element.append(etree.Comment(_describe(spec, None)))
            term_set = etree.SubElement(element, spec.element)
            for example in spec.examples:
                term = etree.SubElement(term_set, term_tag)
                for key, text in example.items():
                    etree.SubElement(term, key).text = text
            continue
        value = _value_text(spec)
        if value is None:
            element.append(etree.Comment(_clean(f"<{spec.element}>: {spec.doc} (optional)")))
            continue
        if not (spec.required or spec.required_element) and spec.default is None:
            element.append(etree.Comment(_clean(f"<{spec.element}>{value}</{spec.element}>: {spec.doc} (optional)")))
            continue
        element.append(etree.Comment(_describe(spec, value)))
        etree.SubElement(element, spec.element).text = value
    return element


def template_tree(tool_element: str) -> etree._Element:
    """``<NMSMPipelineDocument>`` holding the template of ``tool_element``."""
    from nmsm.io.settings import SETTINGS_CLASSES

    root = etree.Element(ROOT, Version=PIPELINE_VERSION_TEXT)
    root.append(block_template(SETTINGS_CLASSES[tool_element], tool_element))
    return root


def format_template(tool_element: str) -> str:
    """The template text (indented XML with an explanatory header comment)."""
    root = template_tree(tool_element)
    etree.indent(root, space="  ")
    header = (
        f"<!-- {tool_element} settings template written by 'nmsm print-xml'. Paths are relative to this file's "
        "folder. Values shown are the parser defaults; required elements show an example. -->\n"
    )
    return header + etree.tostring(root, encoding="unicode") + "\n"

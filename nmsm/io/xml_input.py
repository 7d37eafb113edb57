"""Errors for XML input files (settings, ``.osimx``) that name the line and the fix.

A file saved by Notepad as "ANSI" (Windows-1252) that declares UTF-8, or declares nothing,
has bytes such as ``ü`` that are not UTF-8: libxml2 reports ``ERR_INVALID_ENCODING``, and
the user is told to save it as UTF-8 or to name its encoding (docs/install.md, "Files from
Windows"). Every other syntax error is "malformed XML" at its line.

Every XML file nmsm reads is parsed by :func:`xml_parser`: entities are never substituted,
no DTD is loaded and nothing is fetched from the network, and a file that declares entities
(``<!DOCTYPE r [<!ENTITY ...>]>``: external ones read other files or URLs, nested internal
ones expand without bound) is refused by :func:`refuse_entities` naming the file. OpenSim
and nmsm files declare none.
"""

from __future__ import annotations

import os
from pathlib import Path

from lxml import etree

from nmsm.errors import InputError

#: libxml2's code for bytes that are not valid in the file's (declared or default UTF-8) encoding
ENCODING_ERROR = etree.ErrorTypes.ERR_INVALID_ENCODING


def xml_parser(*, huge_tree: bool = False, **options: bool) -> etree.XMLParser:
    """An lxml parser that reads only the given bytes (nested entity declarations that would
    expand beyond libxml2's amplification limit are a syntax error): no entity substitution, no DTD loading,
    no network access. ``huge_tree`` only for OpenSim models (text nodes over 10 MB);
    ``options``: other :class:`lxml.etree.XMLParser` flags (``remove_blank_text``, ...)."""
    return etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=huge_tree, **options)


def refuse_entities(node: etree._Element | etree._ElementTree, file: str | os.PathLike[str] | None,
                    what: str = "XML file") -> None:
    """Raise :class:`InputError` naming ``file`` when the document of ``node`` declares
    entities, names an external DTD (``<!DOCTYPE r SYSTEM "...">``, never loaded) or holds an
    entity reference left unexpanded."""
    tree = node if isinstance(node, etree._ElementTree) else node.getroottree()
    dtd = tree.docinfo.internalDTD
    names = [entity.name for entity in dtd.iterentities()] if dtd is not None else []
    if tree.docinfo.system_url or tree.docinfo.public_id:
        raise InputError(
            f"the {what} names an external DTD ({tree.docinfo.system_url or tree.docinfo.public_id}) in its "
            "<!DOCTYPE>; nmsm reads no DTD", file=file, line=1, element="<!DOCTYPE>",
            expected="a file without a <!DOCTYPE> (OpenSim and nmsm files have none)")
    names += sorted({entity.name for entity in tree.getroot().iter(etree.Entity)} - set(names))
    if names:
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        raise InputError(
            f"the {what} declares XML entities ({shown}) in its <!DOCTYPE>; nmsm does not expand entities "
            "(they can read other files or network addresses, or grow without bound)",
            file=file, line=1, element="<!DOCTYPE>",
            expected="a file without <!ENTITY> declarations: write their text in place")


def parse_xml_bytes(data: bytes, file: str | os.PathLike[str] | None, *, what: str = "XML file",
                    huge_tree: bool = False, **options: bool) -> etree._Element:
    """The root element of the XML ``data`` read from ``file`` (:func:`xml_parser`); malformed
    XML or declared entities -> :class:`InputError` naming ``file``."""
    try:
        root = etree.fromstring(data, xml_parser(huge_tree=huge_tree, **options))
    except etree.XMLSyntaxError as exc:
        raise xml_input_error(exc, file) from None
    refuse_entities(root, file, what)
    return root


def xml_input_error(exc: etree.XMLSyntaxError, file: str | os.PathLike[str] | None) -> InputError:
    """The :class:`InputError` for a syntax error ``exc`` of the XML file ``file``."""
    if exc.code == ENCODING_ERROR:  # e.g. 'ü' saved by Notepad as "ANSI" (Windows-1252) in a UTF-8 file
        return InputError(
            f"the text is not in the file's encoding ({exc.msg})",
            file=file,
            line=exc.lineno,
            expected="UTF-8 text: save the file as UTF-8, or name its encoding in the first line, e.g. "
            '<?xml version="1.0" encoding="windows-1252"?>',
        )
    return InputError(f"malformed XML: {exc.msg}", file=file, line=exc.lineno, expected="well-formed XML")


def parse_xml_file(path: str | os.PathLike[str], *, what: str = "XML file",
                   remove_blank_text: bool = False) -> etree._Element:
    """The root element of the XML file ``path`` (with line numbers).

    The bytes are read first and parsed from memory: lxml parsing a file by name reports bad
    bytes as an ``OSError`` ("Invalid bytes in character encoding") with no line, while from
    memory they are an ``XMLSyntaxError`` with its line. Unreadable file, bad encoding or
    malformed XML or declared entities -> :class:`InputError` naming the file (``what``:
    "settings file", ...).
    """
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {what}: {exc.strerror or exc}", file=path,
                         expected=f"a readable {what}") from exc
    return parse_xml_bytes(data, path, what=what, remove_blank_text=remove_blank_text)


def element_text(element: etree._Element | None) -> str:
    """The stripped text directly inside ``element``, comments left out.

    lxml's ``element.text`` stops at the first comment: ``<v_max_factor><!-- default 10 -->15
    </v_max_factor>`` has ``text`` None (the ``15`` is the comment's tail), and
    ``<coordinate_list>hip_flexion_r <!-- c --> knee_angle_r</coordinate_list>`` would lose
    ``knee_angle_r``. The text is the element's own text plus the tails of its comments and
    processing instructions, as XPath's ``string()`` reads a text-only element; the text of
    child elements (and their tails) is not part of it.
    """
    if element is None:
        return ""
    parts = [element.text or ""]
    parts.extend(child.tail or "" for child in element if not isinstance(child.tag, str))
    return "".join(parts).strip()


def set_element_text(element: etree._Element, text: str) -> None:
    """Make ``text`` the whole text of ``element`` (comment tails emptied, comments kept)."""
    element.text = text
    for child in element:
        if not isinstance(child.tag, str):
            child.tail = None

"""Every text file nmsm opens names its encoding.

Without ``encoding=``, Python uses the locale's code page: Windows-1252 on a western Windows
(UTF-8 on Linux and macOS), so a results summary naming a folder ``Müller`` is written in
another encoding than the one it is read back with, a settings copy no longer matches its
``<?xml encoding="UTF-8"?>`` declaration, and a name outside the code page (``Łódź``) stops
the write with UnicodeEncodeError after the computation. The rule is checked on the source:
every ``open``/``os.fdopen``/``Path.open`` and ``tempfile.NamedTemporaryFile``/``TemporaryFile``/
``SpooledTemporaryFile`` in text mode, ``read_text`` and ``write_text`` under ``nmsm/`` passes
``encoding=``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "nmsm"


#: tempfile's file factories: the position of their ``mode`` argument (default "w+b", binary)
_TEMPFILES = {"NamedTemporaryFile": 0, "TemporaryFile": 0, "SpooledTemporaryFile": 1}


def _mode(call: ast.Call, position: int, default: str = "r") -> str | None:
    """The literal mode of an open-like call (None when not a literal)."""
    for keyword in call.keywords:
        if keyword.arg == "mode":
            return keyword.value.value if isinstance(keyword.value, ast.Constant) else None
    if len(call.args) > position:
        arg = call.args[position]
        return arg.value if isinstance(arg, ast.Constant) and isinstance(arg.value, str) else None
    return default


def text_calls_without_encoding(source: str) -> list[tuple[int, str]]:
    """``(line, call)`` of the text-mode file calls in ``source`` that do not pass ``encoding=``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
        if any(k.arg == "encoding" or k.arg is None for k in node.keywords):
            continue
        if name in ("read_text", "write_text"):
            if name == "write_text" and len(node.args) != 1:
                continue  # not pathlib's (e.g. ResultsDirectory.write_text(relative, text))
            found.append((node.lineno, name))
        elif name == "open" and isinstance(func, ast.Name) or name == "fdopen":
            mode = _mode(node, 1)
            if mode is not None and "b" not in mode:
                found.append((node.lineno, name))
        elif name == "open" and isinstance(func, ast.Attribute) and not (
            isinstance(func.value, ast.Name) and func.value.id in ("os", "tarfile", "zipfile", "gzip", "webbrowser")
        ):
            mode = _mode(node, 0)  # Path(...).open(mode)
            if mode is not None and "b" not in mode:
                found.append((node.lineno, name))
        elif name in _TEMPFILES:
            mode = _mode(node, _TEMPFILES[name], default="w+b")
            if mode is not None and "b" not in mode:
                found.append((node.lineno, name))
    return sorted(found)


def test_the_checker_sees_each_form() -> None:
    source = (
        "open(p)\nopen(p, 'w')\nopen(p, 'rb')\nopen(p, encoding='utf-8')\nos.fdopen(h, 'w')\n"
        "path.read_text()\npath.write_text(t)\npath.write_text(t, encoding='utf-8')\nresults.write_text(n, t)\n"
        "path.open('w')\npath.open('wb')\nos.open(p, os.O_RDONLY)\nread_text_file(p)\n"
        "tempfile.NamedTemporaryFile('w', suffix='.sto')\nNamedTemporaryFile(mode='w+')\ntempfile.NamedTemporaryFile()\n"
        "tempfile.TemporaryFile('w+')\ntempfile.SpooledTemporaryFile(10, 'w+')\ntempfile.SpooledTemporaryFile(10)\n"
        "tempfile.NamedTemporaryFile('w', encoding='utf-8')\n"
    )
    assert text_calls_without_encoding(source) == [
        (1, "open"), (2, "open"), (5, "fdopen"), (6, "read_text"), (7, "write_text"), (10, "open"),
        (14, "NamedTemporaryFile"), (15, "NamedTemporaryFile"), (17, "TemporaryFile"), (18, "SpooledTemporaryFile")]


@pytest.mark.parametrize("module", sorted(p.relative_to(PACKAGE).as_posix() for p in PACKAGE.rglob("*.py")))
def test_text_files_name_their_encoding(module: str) -> None:
    calls = text_calls_without_encoding((PACKAGE / module).read_text(encoding="utf-8"))
    assert not calls, f"nmsm/{module}: text file calls without encoding= at " + ", ".join(
        f"line {line} ({name})" for line, name in calls)

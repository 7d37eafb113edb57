"""The stamp on every file of results written although their solve did not converge.

A header line ``unconverged=...`` in ``.sto``/``.mot`` tables, an XML comment
``UNCONVERGED: ...`` after the declaration of ``.osim``/``.osimx``/``.xml`` files, a first line
``UNCONVERGED: ...`` in ``.txt``/``.log`` files and an ``"unconverged"`` entry in JSON objects;
other files (figures) are left as they are. The policy that decides when to stamp is
:mod:`nmsm.core.unconverged`; the results folder's staging stamps
(:meth:`nmsm.core.results.ResultsDirectory.task`).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

_XML_SUFFIXES = (".osim", ".osimx", ".xml")
_TEXT_SUFFIXES = (".txt", ".log")
_TABLE_SUFFIXES = (".sto", ".mot")


def stamp_unconverged(folder: Path, note: str) -> None:
    """Stamp every file under ``folder`` as unconverged with the one-line ``note`` (module docstring)."""
    line = " ".join(note.split())
    for path in sorted(p for p in folder.rglob("*") if p.is_file()):
        suffix = path.suffix.lower()
        if suffix in _TABLE_SUFFIXES:
            _stamp_table(path, line)
        elif suffix in _XML_SUFFIXES:
            _stamp_xml(path, line)
        elif suffix in _TEXT_SUFFIXES:
            text = path.read_text(encoding="utf-8", errors="surrogateescape")
            path.write_text(f"UNCONVERGED: {line}\n{text}", encoding="utf-8", errors="surrogateescape")
        elif suffix == ".json":
            _stamp_json(path, line)


def _stamp_table(path: Path, line: str) -> None:
    lines = path.read_text(encoding="utf-8", errors="surrogateescape").splitlines(keepends=True)
    end = next((i for i, text in enumerate(lines) if text.strip().lower() == "endheader"), None)
    if end is None:
        return
    lines.insert(end, f"unconverged={line}\n")
    path.write_text("".join(lines), encoding="utf-8", errors="surrogateescape")


def _stamp_xml(path: Path, line: str) -> None:
    text = path.read_text(encoding="utf-8", errors="surrogateescape")
    comment = f"<!-- UNCONVERGED: {re.sub('-{2,}', '-', line).rstrip('-')} -->\n"
    declaration = re.match(r"\s*<\?xml[^>]*\?>\s*", text)
    at = declaration.end() if declaration else 0
    path.write_text(text[:at] + comment + text[at:], encoding="utf-8", errors="surrogateescape")


def _stamp_json(path: Path, line: str) -> None:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, UnicodeDecodeError):
        return
    if isinstance(data, dict):
        path.write_text(json.dumps({"unconverged": line, **data}, indent=1), encoding="utf-8")

"""Decoding the text of data files (``.trc``, ``.sto``, ``.mot``) written on any system.

The rule (also in docs/install.md, "Files from Windows"):

* UTF-8, with or without a byte-order mark (Notepad and Excel's "CSV UTF-8" write one);
* UTF-16 with a byte-order mark (Excel's "Unicode Text" on Windows);
* anything else that is not valid UTF-8 is read as Windows-1252 (the "ANSI" code page of
  western Windows, where ``°`` or ``ü`` are single bytes), with a warning naming the file
  and the first line that is not UTF-8.

Line endings (``\\n``, ``\\r\\n``, ``\\r``) are all accepted by the parsers, which split with
:meth:`str.splitlines`. The result never starts with a byte-order mark.
"""

from __future__ import annotations

import codecs
import os
import warnings
from pathlib import Path

#: byte-order mark as a character (left at the start of text decoded as plain UTF-8)
BOM = "\ufeff"


def decode_text(data: bytes, source: str | os.PathLike[str] | None = None, *, warn: bool = True) -> str:
    """``data`` decoded by the rule of the module docstring (``source`` names the file in the
    warning; ``warn=False``: none, for a second reading of a file already read)."""
    if data.startswith(codecs.BOM_UTF8):
        data = data[len(codecs.BOM_UTF8):]
    elif data.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return data.decode("utf-16", errors="replace").lstrip(BOM)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        if warn:
            warnings.warn(
                f"{source or 'text'}:{line}: not UTF-8 text (byte 0x{data[exc.start]:02x}); read as Windows-1252",
                stacklevel=3,
            )
        return data.decode("cp1252", errors="replace")


def read_text_file(path: str | os.PathLike[str], *, warn: bool = True) -> str:
    """The decoded text of ``path`` (module docstring); :class:`OSError` as :meth:`Path.read_bytes` raises it."""
    path = Path(path)
    return decode_text(path.read_bytes(), path, warn=warn)

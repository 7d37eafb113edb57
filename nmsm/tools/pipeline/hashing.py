"""Content digests of the files and folders a stage reads.

A stage is up to date when the digest of its inputs equals the one recorded when it last
finished. The digest covers file *contents*, never times or absolute locations, so a
results tree that was moved (or a data folder copied elsewhere) is still up to date.

* a file: SHA-256 of its bytes;
* a folder: SHA-256 over its files in sorted relative-path order, each as
  ``relative path`` + the file's digest; hidden entries (``.staging-*`` folders of
  :class:`~nmsm.core.results.ResultsDirectory`) and ``plots`` folders (figures drawn from
  the results, e.g. by ``nmsm report``) are left out;
* a missing path: the text ``missing:<name>`` (so a file that appears later changes it);
* nmsm's own code: :func:`code_digest` over its Python sources (part of every stage's
  input digest, so results made by another version of nmsm are redone).

Digests are hex strings. Files are read in 1 MiB blocks; :class:`DigestCache` remembers the
digest of a file by ``(path, size, mtime_ns)`` within one pipeline run, so a data folder
read by several stages is hashed once.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable
from pathlib import Path

_BLOCK = 1 << 20
#: folders of figures drawn from results (``nmsm plot``, ``nmsm report``): derived, not hashed
FIGURES = "plots"


def _is_hidden(name: str) -> bool:
    return name.startswith(".")


class DigestCache:
    """File digests keyed by ``(resolved path, size, mtime_ns)``.

    ``exclude``: folders left out of every folder digest (the pipeline's own results
    directory, when an input folder contains it).
    """

    def __init__(self, exclude: Iterable[Path] = ()) -> None:
        self._files: dict[tuple[str, int, int], str] = {}
        self.exclude = {Path(p).resolve() for p in exclude}

    def file(self, path: Path) -> str:
        """SHA-256 (hex) of a file's bytes."""
        stat = path.stat()
        key = (str(path.resolve()), stat.st_size, stat.st_mtime_ns)
        cached = self._files.get(key)
        if cached is not None:
            return cached
        digest = hashlib.sha256()
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(_BLOCK), b""):
                digest.update(block)
        value = digest.hexdigest()
        self._files[key] = value
        return value

    def folder(self, path: Path) -> str:
        """SHA-256 (hex) over the folder's visible files (see module docstring)."""
        digest = hashlib.sha256()
        for relative, file in _visible_files(path, self.exclude):
            digest.update(relative.encode())
            digest.update(b"\0")
            digest.update(self.file(file).encode())
            digest.update(b"\n")
        return digest.hexdigest()

    def path(self, path: Path) -> str:
        """Digest of a file, a folder or a missing path."""
        if path.is_file():
            return "file:" + self.file(path)
        if path.is_dir():
            return "dir:" + self.folder(path)
        return f"missing:{path.name}"


def _visible_files(root: Path, exclude: set[Path]) -> Iterable[tuple[str, Path]]:
    """``(relative posix path, path)`` of every file under ``root`` not inside a hidden entry
    or an excluded folder, sorted."""
    found: list[tuple[str, Path]] = []
    for folder, dirs, files in os.walk(root):
        base = Path(folder)
        dirs[:] = sorted(d for d in dirs if not _is_hidden(d) and d != FIGURES
                         and (base / d).resolve() not in exclude)
        for name in files:
            if _is_hidden(name):
                continue
            file = base / name
            found.append((file.relative_to(root).as_posix(), file))
    found.sort(key=lambda item: item[0])
    return found


_CODE_DIGEST: str | None = None
#: packages of nmsm that cannot change a stage's results (examples write settings, which are hashed;
#: the batch hands settings files to the tools)
_NOT_RESULTS = ("examples", "report", "plots", "batch")


def code_digest() -> str:
    """SHA-256 (hex) of nmsm's own Python sources (but :data:`_NOT_RESULTS`): a stage made by
    other code is redone (after an upgrade, or while developing nmsm)."""
    global _CODE_DIGEST
    if _CODE_DIGEST is None:
        root = Path(__file__).resolve().parents[2]  # the nmsm package
        digest = hashlib.sha256()
        for file in sorted(root.rglob("*.py")):
            if file.relative_to(root).parts[0] in _NOT_RESULTS:
                continue
            digest.update(file.relative_to(root).as_posix().encode())
            digest.update(file.read_bytes())
        _CODE_DIGEST = digest.hexdigest()
    return _CODE_DIGEST


def text_digest(*parts: str) -> str:
    """SHA-256 (hex) of text parts joined by NUL characters."""
    digest = hashlib.sha256()
    for part in parts:
        digest.update(part.encode())
        digest.update(b"\0")
    return digest.hexdigest()

"""Resolve a path written in a settings file.

Settings files written on Windows use back-slashes and sometimes the wrong letter case
(``Preprocessing`` for ``preprocessing``). A relative path is looked up, in order:

1. relative to ``base`` (default: the folder holding the settings file);
2. relative to that folder's parent, when no explicit ``base`` was given: the tutorial's
   ``CompletedSettingsFiles/*.xml`` name inputs of the step folder above them;
3. relative to the current working directory, when no explicit ``base`` was given (the
   MATLAB original resolves every path against ``pwd``).

In each folder the exact spelling wins; otherwise each path component is matched
case-insensitively (a warning names both spellings). Falling back to (2) or (3) warns too.
A path that must exist and is found nowhere raises :class:`InputError` naming the settings
file, line, element and every location tried.

Separators: ``\\`` and ``/`` are the same everywhere (settings of the original MATLAB tool
use back-slashes), so a back-slash in a settings path always separates folders, also on
Linux and macOS, where it would otherwise be a legal character of a file name. An absolute
Windows path (``C:\\Users\\...``, ``\\\\server\\share\\...``) names nothing on Linux or
macOS: there it raises :class:`InputError` naming the element, before anything is read or
written (a results folder would otherwise become a folder named ``C:``).
"""

from __future__ import annotations

import os
import re
import sys
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

from nmsm.errors import InputError

#: what a resolved path must be
KINDS = ("any", "file", "dir")
#: whether paths are Windows paths here (a constant, so tests can pretend either way)
ON_WINDOWS = os.name == "nt"
_WINDOWS_DRIVE = re.compile(r"^[A-Za-z]:([\\/]|$)")


def windows_absolute(text: str) -> str | None:
    """What makes ``text`` an absolute Windows path (``drive C:`` or ``network share``), else None."""
    stripped = text.strip()
    if _WINDOWS_DRIVE.match(stripped):
        return f"drive {stripped[:2]}"
    if stripped.startswith("\\\\"):
        return "network share"
    return None


def check_not_windows_absolute(
    text: str,
    *,
    settings_file: str | os.PathLike[str] | None = None,
    line: int | None = None,
    element: str | None = None,
) -> None:
    """:class:`InputError` when ``text`` is an absolute Windows path and this is not Windows."""
    if ON_WINDOWS:
        return
    what = windows_absolute(text)
    if what is None:
        return
    system = "macOS" if sys.platform == "darwin" else "Linux" if sys.platform.startswith("linux") else sys.platform
    raise InputError(
        f"'{text.strip()}' is an absolute Windows path ({what}), which names no file or folder on {system}",
        file=settings_file,
        line=line,
        element=element,
        expected="a path relative to the settings file's folder (e.g. ..\\data\\model.osim) or an absolute "
        "path of this system (e.g. /home/...)",
    )


def normalize_separators(text: str) -> str:
    """``text`` stripped, with Windows back-slashes turned into ``/``."""
    return text.strip().replace("\\", "/")


def _kind_ok(path: Path, kind: str) -> bool:
    if kind == "file":
        return path.is_file()
    if kind == "dir":
        return path.is_dir()
    return path.exists()


def match_case_insensitive(base: Path, relative: Path, kind: str = "any") -> Path | None:
    """``base / relative`` with each missing component matched case-insensitively.

    Returns the existing path, or ``None``. Raises :class:`InputError` when a component
    matches several entries that differ only in case.
    """
    current = base
    for part in relative.parts:
        if part in ("", "."):
            continue
        if part == "..":
            current = current.parent
            continue
        exact = current / part
        if exact.exists():
            current = exact
            continue
        if not current.is_dir():
            return None
        lowered = part.lower()
        found = sorted(e for e in os.listdir(current) if e.lower() == lowered)
        if not found:
            return None
        if len(found) > 1:
            raise InputError(
                f"'{part}' matches several entries of {current} that differ only in case: {', '.join(found)}",
                expected="a path spelled exactly as on disk",
            )
        current = current / found[0]
    return current if _kind_ok(current, kind) else None


def _describe(kind: str) -> str:
    return {"file": "an existing file", "dir": "an existing folder"}.get(kind, "an existing file or folder")


def resolve_path(
    text: str,
    *,
    settings_file: str | os.PathLike[str] | None = None,
    line: int | None = None,
    element: str | None = None,
    base: str | os.PathLike[str] | None = None,
    must_exist: bool = True,
    kind: str = "any",
    on_fallback: Callable[[str, Path, str], None] | None = None,
) -> Path:
    """The path that ``text`` (as written in a settings file) names.

    ``base`` replaces the settings file's folder as the first place to look (e.g. GCP's
    ``input_directory``); with an explicit ``base`` no fallback folder is tried. With
    ``must_exist=False`` a missing path resolves to ``base / text`` (outputs).
    ``on_fallback(text, found, where)`` replaces the warning issued when a path is found only
    relative to a fallback folder (a settings document warns once per file).
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}")
    where = f"<{element}>" if element and not element.startswith("<") else element
    check_not_windows_absolute(text, settings_file=settings_file, line=line, element=where)
    cleaned = normalize_separators(text)
    path = Path(cleaned)
    settings_dir = Path(settings_file).resolve().parent if settings_file else Path.cwd()
    candidates: Sequence[tuple[Path, str | None]]
    if path.is_absolute():
        relative = path.relative_to(path.anchor)
        candidates = [(Path(path.anchor), None)]
    else:
        relative = path
        if base is not None:
            candidates = [(Path(base), None)]
        else:
            candidates = [
                (settings_dir, None),
                (settings_dir.parent, "the parent of the settings file's folder"),
                (Path.cwd(), "the current working directory"),
            ]
    seen: set[Path] = set()
    tried: list[str] = []
    for folder, fallback in candidates:
        folder = folder.resolve() if folder.is_absolute() else (settings_dir / folder).resolve()
        if folder in seen:
            continue
        seen.add(folder)
        exact = folder / relative
        tried.append(str(exact))
        if _kind_ok(exact, kind):
            if fallback:
                _fallback(on_fallback, text, exact, fallback, settings_file, line, where)
            return exact
        try:
            found = match_case_insensitive(folder, relative, kind)
        except InputError as exc:
            raise InputError(exc.detail, file=settings_file, line=line, element=where, expected=exc.expected) from None
        if found is not None:
            warnings.warn(
                f"{_loc(settings_file, line, where)}path '{text.strip()}' does not exist with this letter case; "
                f"using '{found}' (spelled '{found.relative_to(folder)}' on disk)",
                stacklevel=2,
            )
            if fallback:
                _fallback(on_fallback, text, found, fallback, settings_file, line, where)
            return found
        if not must_exist:
            break
    if not must_exist:
        first = candidates[0][0]
        first = first if first.is_absolute() else settings_dir / first
        return (first / relative).resolve()
    if path.is_absolute():
        rule = ""
    elif base is not None:
        rule = f" (relative paths are relative to {(settings_dir / Path(base)).resolve()})"
    else:
        rule = (" (relative paths are looked up in the settings file's folder, then in its parent folder"
                " and the current working directory)")
    raise InputError(
        f"'{text.strip()}' not found (tried {'; '.join(tried)})",
        file=settings_file,
        line=line,
        element=where,
        expected=_describe(kind) + rule,
    )


def _loc(settings_file: object, line: int | None, where: str | None) -> str:
    out = ""
    if settings_file:
        out = f"{settings_file}:{line}: " if line else f"{settings_file}: "
    if where:
        out += f"{where}: "
    return out


def _fallback(
    handler: Callable[[str, Path, str], None] | None,
    text: str,
    found: Path,
    fallback: str,
    settings_file: object,
    line: int | None,
    where: str | None,
) -> None:
    if handler is not None:
        handler(text, found, fallback)
        return
    warnings.warn(
        f"{_loc(settings_file, line, where)}'{text.strip()}' is not next to the settings file; "
        f"found it relative to {fallback}: {found}",
        stacklevel=4,
    )

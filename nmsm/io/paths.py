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
Parts are followed one by one as the file system does: ``..`` is the parent of the folder
reached so far (so a path may leave the settings file's folder), every part but the last must
be a folder, and the last must be of the kind asked for (file or folder). An output path that
does not exist yet continues below its longest existing part, matched the same way, so that a
results folder lands inside ``Preprocessing`` when the settings say ``preprocessing``.
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

import attrs

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


#: the longest file or folder name (bytes) of common file systems (ext4, NTFS, APFS)
NAME_MAX = 255


def check_name_lengths(path: Path, *, settings_file: str | os.PathLike[str] | None = None, line: int | None = None,
                       element: str | None = None) -> None:
    """Refuse a path with a file or folder name longer than :data:`NAME_MAX` bytes (the
    operating system would refuse to look it up, with ``OSError`` ENAMETOOLONG)."""
    for part in path.parts:
        if len(os.fsencode(part)) > NAME_MAX:
            shown = part[:40] + "..." + part[-20:]
            raise InputError(f"the name '{shown}' in the path is {len(os.fsencode(part))} bytes long", file=settings_file,
                             line=line, element=element,
                             expected=f"file and folder names of at most {NAME_MAX} bytes")


def _kind_ok(path: Path, kind: str) -> bool:
    if kind == "file":
        return path.is_file()
    if kind == "dir":
        return path.is_dir()
    return path.exists()


@attrs.frozen
class Walk:
    """Where following a relative path's parts from a folder led.

    ``path`` has no ``.`` or ``..`` parts; ``spelled`` is the relative path as spelled on disk
    (``..`` parts kept); ``renamed`` is true when a part matched only case-insensitively;
    ``complete`` is false when a part was missing (``path`` then ends with the parts as written).
    """

    path: Path
    spelled: str
    renamed: bool
    complete: bool


def _entries(folder: Path, part: str, last: bool, kind: str) -> list[str]:
    """Entries of ``folder`` spelled like ``part`` but for letter case, of the kind a path part needs."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    lowered = part.lower()
    wanted = kind if last else "dir"
    return sorted(n for n in names if n.lower() == lowered and _kind_ok(folder / n, wanted))


def walk(
    base: Path, relative: Path, kind: str = "any", *, ignore_case: bool = True, partial: bool = False
) -> Walk | None:
    """Follow ``relative`` from the folder ``base`` part by part, as the file system does.

    ``..`` goes to the parent of the folder reached so far (its real location, as the operating
    system does after a symbolic link). A part that does not exist is matched case-insensitively
    (``ignore_case``), among folders for every part but the last and among entries of ``kind``
    for the last. Returns ``None`` when a part is missing, or, with ``partial``, a
    :class:`Walk` whose path continues with the remaining parts as written. Raises
    :class:`InputError` when a part matches several entries that differ only in case.
    """
    parts = [p for p in relative.parts if p not in ("", ".")]
    current = base
    spelled: list[str] = []
    renamed = False
    for position, part in enumerate(parts):
        last = position == len(parts) - 1
        if part == "..":
            if not current.is_dir():
                break
            current = Path(os.path.realpath(current)).parent
            spelled.append(part)
            continue
        exact = current / part
        if _kind_ok(exact, kind if last else "dir"):
            current = exact
            spelled.append(part)
            continue
        found = _entries(current, part, last, kind) if ignore_case and current.is_dir() else []
        if len(found) > 1:
            raise InputError(
                f"'{part}' matches several entries of {current} that differ only in case: {', '.join(found)}",
                expected="a path spelled exactly as on disk",
            )
        if not found:
            break
        current = current / found[0]
        spelled.append(found[0])
        renamed = True
    else:
        if _kind_ok(current, kind):
            return Walk(current, "/".join(spelled), renamed, True)
    if not partial:
        return None
    rest = parts[len(spelled):]
    return Walk(Path(os.path.normpath(current.joinpath(*rest))), "/".join(spelled + rest), renamed, False)


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
    ``must_exist=False`` a missing path resolves below its longest existing part (outputs).
    ``on_fallback(text, found, where)`` replaces the warning issued when a path is found only
    relative to a fallback folder (a settings document warns once per file).
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}")
    where = f"<{element}>" if element and not element.startswith("<") else element
    check_not_windows_absolute(text, settings_file=settings_file, line=line, element=where)
    cleaned = normalize_separators(text)
    path = Path(cleaned)
    check_name_lengths(path, settings_file=settings_file, line=line, element=where)
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
        tried.append(str(folder / relative))
        try:
            found = walk(folder, relative, kind)
        except InputError as exc:
            raise InputError(exc.detail, file=settings_file, line=line, element=where, expected=exc.expected) from None
        if found is not None:
            if found.renamed:
                _warn_case(text, found, settings_file, line, where)
            if fallback:
                _fallback(on_fallback, text, found.path, fallback, settings_file, line, where)
            return found.path
        if not must_exist:
            break
    if not must_exist:
        first = candidates[0][0]
        first = first.resolve() if first.is_absolute() else (settings_dir / first).resolve()
        try:
            output = walk(first, relative, "any", partial=True)
        except InputError as exc:
            raise InputError(exc.detail, file=settings_file, line=line, element=where, expected=exc.expected) from None
        assert output is not None
        if output.renamed:
            _warn_case(text, output, settings_file, line, where)
        return output.path
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


def _warn_case(text: str, found: Walk, settings_file: object, line: int | None, where: str | None) -> None:
    warnings.warn(
        f"{_loc(settings_file, line, where)}path '{text.strip()}' does not exist with this letter case; "
        f"using '{found.path}' (spelled '{found.spelled}' on disk)",
        stacklevel=4,
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

"""Find a trial's files in a data folder by its prefix.

The original matches prefixes as substrings, so ``gait_1`` also matches ``gait_10``. Here
an exact stem match wins (``gait_1.sto``); else a name containing the prefix is used when it
is the only one (``gait_1_muscleActivations.sto``, ``S01_gait_1.mot``), but the prefix never
runs into a neighbouring digit: a prefix ending in a digit does not match where another
digit follows (``gait_1`` is not in ``gait_10.sto``), one starting with a digit not where a
digit precedes (``1_gait`` is not in ``11_gait.sto``) (:func:`contains_trial`). Several
candidates are an error listing them.

Layout (docs/guide.md, section 2): ``<data>/IKData/<prefix>.sto``, ``IDData/``, ``EMGData/``,
``GRFData/``, ``MAData/<prefix>/<prefix>_..._Length.sto`` etc.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from nmsm.errors import InputError

#: extensions of OpenSim tables
TABLE_EXTENSIONS = (".sto", ".mot")


def _entries(directory: Path, *, folders: bool, extensions: Sequence[str]) -> list[Path]:
    if not directory.is_dir():
        raise InputError(f"folder not found: {directory}", file=directory, expected="an existing data folder")
    out = []
    for entry in sorted(directory.iterdir()):
        if entry.name.startswith("."):
            continue
        if folders and entry.is_dir():
            out.append(entry)
        elif not folders and entry.is_file() and entry.suffix.lower() in extensions:
            out.append(entry)
    return out


def trial_prefixes(directory: str | os.PathLike[str], extensions: Sequence[str] = TABLE_EXTENSIONS) -> list[str]:
    """Trial prefixes found in ``directory``: table file names without extension, sorted."""
    return [p.stem for p in _entries(Path(directory), folders=False, extensions=tuple(e.lower() for e in extensions))]


def contains_trial(name: str, prefix: str) -> bool:
    """Whether file or folder ``name`` contains trial ``prefix`` without running into a digit.

    ``gait_1`` is in ``gait_1_ID.sto`` and ``S01_gait_1.mot``, not in ``gait_10.sto``;
    ``1_gait`` is not in ``11_gait.sto``.
    """
    if not prefix:
        return False
    start = name.find(prefix)
    while start >= 0:
        end = start + len(prefix)
        digit_before = prefix[0].isdigit() and start > 0 and name[start - 1].isdigit()
        digit_after = prefix[-1].isdigit() and end < len(name) and name[end].isdigit()
        if not (digit_before or digit_after):
            return True
        start = name.find(prefix, start + 1)
    return False


def _match(candidates: list[Path], prefix: str, key, directory: Path, what: str) -> Path:
    exact = [p for p in candidates if key(p) == prefix]
    if len(exact) == 1:
        return exact[0]
    if len(exact) > 1:
        raise InputError(
            f"several {what}s named '{prefix}': {', '.join(p.name for p in exact)}",
            file=directory,
            expected=f"one {what} per trial",
        )
    containing = [p for p in candidates if contains_trial(p.name, prefix)]
    if len(containing) == 1:
        return containing[0]
    if not containing:
        names = ", ".join(p.name for p in candidates) or "(empty folder)"
        raise InputError(
            f"no {what} for trial '{prefix}' (found: {names})",
            file=directory,
            expected=f"a {what} whose name is, or contains, '{prefix}' (not next to another digit)",
        )
    raise InputError(
        f"trial '{prefix}' is ambiguous: {', '.join(p.name for p in containing)} all contain it",
        file=directory,
        expected=f"a {what} named exactly '{prefix}', or a prefix contained in one name only",
    )


def find_trial_file(
    directory: str | os.PathLike[str], prefix: str, *, extensions: Sequence[str] = TABLE_EXTENSIONS
) -> Path:
    """The table of trial ``prefix`` in ``directory`` (exact stem, else the one name containing it, see
    :func:`contains_trial`)."""
    directory = Path(directory)
    exts = tuple(e.lower() for e in extensions)
    return _match(_entries(directory, folders=False, extensions=exts), prefix, lambda p: p.stem, directory, "file")


def find_trial_folder(directory: str | os.PathLike[str], prefix: str) -> Path:
    """The sub-folder of trial ``prefix`` in ``directory`` (e.g. ``MAData/<prefix>``)."""
    directory = Path(directory)
    return _match(_entries(directory, folders=True, extensions=()), prefix, lambda p: p.name, directory, "folder")


def find_file_by_suffix(
    directory: str | os.PathLike[str], suffix: str, *, extensions: Sequence[str] = TABLE_EXTENSIONS
) -> Path:
    """The one table in ``directory`` whose stem ends with ``suffix`` (e.g. ``_Length``, ``_MomentArm_knee_angle_r``)."""
    directory = Path(directory)
    exts = tuple(e.lower() for e in extensions)
    found = [p for p in _entries(directory, folders=False, extensions=exts) if p.stem.endswith(suffix)]
    if len(found) == 1:
        return found[0]
    if not found:
        raise InputError(f"no file ending in '{suffix}'", file=directory, expected=f"a table named '*{suffix}.sto'")
    raise InputError(
        f"several files end in '{suffix}': {', '.join(p.name for p in found)}",
        file=directory,
        expected=f"one table named '*{suffix}.sto'",
    )

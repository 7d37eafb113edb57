"""The file written by ``nmsm print-xml -o`` and ``nmsm upgrade-settings -o``: checked, then
written atomically.

Before anything is written (:func:`check_output`):

* the output's folder must exist (it is not created: a typo in it must not make folders);
* the output must not name a folder;
* an existing file is replaced only with ``--force``;
* *protected* files are never replaced, ``--force`` or not: the settings file being upgraded
  and every file it names (solver settings, model, data files). They are compared by
  identity (:func:`os.path.samefile`: the same inode), so another spelling, a symbolic
  link or a hard link of them is refused too; an existing file inside a *protected folder*
  (a data folder the settings read) is refused as well.

:func:`write_output` writes the text into a temporary file in the output's folder and moves
it into place with :func:`os.replace`, so a failure leaves the earlier file (or none), never
a half-written one.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Mapping
from pathlib import Path

from nmsm.errors import InputError

#: how the messages name the option
OPTION = "-o"


def _same_file(a: Path, b: Path) -> bool:
    """Whether ``a`` and ``b`` are one file (same inode) or, when one does not exist, spell the same path."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b) or a.resolve() == b.resolve()


def check_output(
    path: str | os.PathLike[str],
    *,
    force: bool = False,
    protected: Mapping[Path, str] | None = None,
    protected_folders: Mapping[Path, str] | None = None,
    example_name: str = "NEW.xml",
) -> Path:
    """``path`` as a :class:`Path` when it may be written, else :class:`InputError`.

    ``protected``: files never replaced -> what each is (for the message, e.g. "the solver
    settings file that OLD.xml names in <optimal_control_settings_file> (line 14)");
    ``protected_folders``: folders whose existing files are never replaced -> what each is.
    ``example_name``: a file name suggested when ``path`` is a folder.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(
            f"{OPTION} names a folder, not a file",
            file=path,
            expected=f"the name of the file to write, e.g. {path / example_name}",
        )
    folder = path.parent
    if not folder.exists():
        raise InputError(
            f"cannot write the output file: its folder {folder} does not exist",
            file=path,
            expected=f"{OPTION} naming a file in an existing folder: create {folder} first or fix the path",
        )
    if not folder.is_dir():
        raise InputError(
            f"cannot write the output file: {folder} is a file, not a folder",
            file=path,
            expected=f"{OPTION} naming a file in an existing folder",
        )
    for other, what in (protected or {}).items():
        if _same_file(path, Path(other)):
            raise InputError(
                f"the output file is {what}: writing it would overwrite an input",
                file=path,
                expected="another output file name; --force never replaces an input",
            )
    exists = path.exists() or path.is_symlink()
    if exists:
        real = path.resolve()
        for inputs, what in (protected_folders or {}).items():
            if real.is_relative_to(Path(inputs).resolve()):
                raise InputError(
                    f"the output file already exists inside {what} ({inputs}): writing it would overwrite an input",
                    file=path,
                    expected="another output file name; --force never replaces an input",
                )
        if not force:
            raise InputError(
                "the output file already exists",
                file=path,
                expected="a new file name, or --force to replace it",
            )
    return path


def write_output(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (see module docstring); an
    :class:`InputError` naming ``path`` when the folder is not writable."""
    try:
        mode = stat.S_IMODE(path.stat().st_mode) if path.is_file() else None
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise InputError(
            f"cannot write the output file: {exc.strerror or exc}", file=path, expected="a writable folder"
        ) from None
    try:
        with os.fdopen(handle, "w", encoding="utf-8") as out:
            out.write(text)
            out.flush()
            os.fsync(out.fileno())
        if mode is None:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(temporary, mode)
        os.replace(temporary, path)
    except BaseException as exc:
        Path(temporary).unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise InputError(
                f"cannot write the output file: {exc.strerror or exc}", file=path, expected="a writable folder"
            ) from None
        raise

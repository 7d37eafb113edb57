"""Output paths of the ``nmsm`` commands: checked before anything is computed, written atomically.

Before anything is written (:func:`check_output`, :func:`check_output_folder`):

* the output's folder must exist: no command creates missing folders above the file or
  folder it was told to write (a typo in a path must not make folders);
* an output file must not name a folder, an output folder must not name a file;
* *protected* files are never replaced: every input of the command (and, for
  ``print-xml``/``upgrade-settings``, every file the settings name). They are compared by
  identity (:func:`os.path.samefile`: the same inode), so another spelling, a symbolic link
  or a hard link of an input is refused too; an existing file inside a *protected folder*
  (a data folder the command reads) is refused as well;
* an existing file that is none of these is replaced only with ``force`` (``print-xml`` and
  ``upgrade-settings`` ask for ``--force``; the other commands replace their earlier output).

:func:`write_output` (text) and :func:`write_atomically` (any writer) write into a temporary
file in the output's folder and move it into place with :func:`os.replace`, so a failure
leaves the earlier file (or none), never a half-written one.

:func:`staged_outputs` does the same for the several files of one command (``muscle-analysis``,
``plot``, ``surrogate --write-samples``, ``export --loads``): they are written into hidden
staging folders inside the folders they go to (the same filesystem) and moved into place only
when every one is complete. A failure or a stop (``KeyboardInterrupt``) before that, or while
moving, leaves the earlier files as they were and removes the staged files and the folders the
command created.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import TypeVar

from nmsm.errors import InputError

#: how the messages name the option, unless told otherwise
OPTION = "-o"
_T = TypeVar("_T")


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether ``a`` and ``b`` are one file (same inode) or, when one does not exist, spell the same path."""
    a, b = Path(a), Path(b)
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b) or a.resolve() == b.resolve()



def read_only_folder(folder: str | os.PathLike[str]) -> bool:
    """Whether ``folder`` is read-only: on a read-only filesystem, without a write permission bit
    for anyone (``chmod a-w``: honoured even when running as root, who could write it anyway),
    or not writable by this user. A missing folder is not read-only."""
    folder = Path(folder)
    try:
        mode = folder.stat().st_mode
    except OSError:
        return False
    if not mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH) or not os.access(folder, os.W_OK):
        return True
    try:
        return bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):
        return False


def check_default_folder_writable(folder: str | os.PathLike[str], what: str, option: str = OPTION) -> None:
    """:class:`InputError` when a command's default output would go into the read-only ``folder``
    (e.g. a shipped results folder): ``what`` names that output; the message asks for ``option``."""
    if read_only_folder(folder):
        raise InputError(
            f"the results folder is read-only: {what} would be written into it by default; nothing was written",
            file=Path(folder),
            expected=f"{option} naming a writable place for {what}",
        )


def _check_parent(path: Path, option: str, kind: str) -> None:
    """:class:`InputError` when the folder ``path`` would go in is missing or is a file."""
    folder = path.parent
    if not folder.exists():
        raise InputError(
            f"cannot write the output {kind}: its folder {folder} does not exist",
            file=path,
            expected=f"{option} naming a {kind} in an existing folder: create {folder} first or fix the path",
        )
    if not folder.is_dir():
        raise InputError(
            f"cannot write the output {kind}: {folder} is a file, not a folder",
            file=path,
            expected=f"{option} naming a {kind} in an existing folder",
        )


def check_output(
    path: str | os.PathLike[str],
    *,
    force: bool = False,
    protected: Mapping[Path, str] | None = None,
    protected_folders: Mapping[Path, str] | None = None,
    example_name: str = "NEW.xml",
    option: str = OPTION,
    force_option: bool = True,
    name_option: bool = False,
) -> Path:
    """``path`` as a :class:`Path` when it may be written, else :class:`InputError`.

    ``protected``: files never replaced -> what each is (for the message, e.g. "the solver
    settings file that OLD.xml names in <optimal_control_settings_file> (line 14)");
    ``protected_folders``: folders whose existing files are never replaced -> what each is.
    ``example_name``: a file name suggested when ``path`` is a folder; ``option``: how the
    messages name the option (``-o``, ``--errors``, ...); ``force_option``: whether the
    command has ``--force`` (the messages then say it never replaces an input);
    ``name_option``: an input refused is reported as "the output file (OPTION) is ...".
    """
    path = Path(path)
    never = "another output file name" + ("; --force never replaces an input" if force_option else "")
    if path.is_dir():
        raise InputError(
            f"{option} names a folder, not a file",
            file=path,
            expected=f"the name of the file to write, e.g. {path / example_name}",
        )
    _check_parent(path, option, "file")
    named = f"the output file ({option})" if name_option else "the output file"
    for other, what in (protected or {}).items():
        if same_file(path, Path(other)):
            raise InputError(f"{named} is {what}: writing it would overwrite an input", file=path, expected=never)
    exists = path.exists() or path.is_symlink()
    if exists:
        real = path.resolve()
        for inputs, what in (protected_folders or {}).items():
            if real.is_relative_to(Path(inputs).resolve()):
                raise InputError(
                    f"{named} already exists inside {what} ({inputs}): writing it would overwrite an input",
                    file=path,
                    expected=never,
                )
        if not force:
            raise InputError(
                "the output file already exists",
                file=path,
                expected="a new file name, or --force to replace it",
            )
    return path


def check_outputs(
    outputs: Mapping[str, str | os.PathLike[str] | None],
    inputs: Mapping[Path, str],
    *,
    protected_folders: Mapping[Path, str] | None = None,
    example_names: Mapping[str, str] | None = None,
) -> dict[str, Path]:
    """Check every output file of a command before it computes anything.

    ``outputs``: option (``-o``, ``--errors``) -> path (None: not written); ``inputs``: the
    command's input files -> what each is (they are never replaced). Existing files that are
    no input are replaced (the commands rewrite their earlier output). Two options naming one
    file are refused too. Returns option -> :class:`Path` of the outputs given.
    """
    checked: dict[str, Path] = {}
    for option, raw in outputs.items():
        if raw is None:
            continue
        path = check_output(raw, force=True, protected=inputs, protected_folders=protected_folders,
                            example_name=(example_names or {}).get(option, "OUTPUT"), option=option,
                            force_option=False, name_option=True)
        for other, earlier in checked.items():
            if same_file(path, earlier):
                raise InputError(f"{option} and {other} name the same file", file=path,
                                 expected=f"a different file for {option} and {other}")
        checked[option] = path
    return checked


def check_output_folder(
    path: str | os.PathLike[str],
    *,
    option: str = OPTION,
    what: str = "the output folder",
) -> Path:
    """``path`` as a :class:`Path` when it may be used as an output folder (an existing folder,
    or a new one whose parent exists: it is created when written), else :class:`InputError`."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{option} names a file, not a folder", file=path, expected=what)
    if not path.exists():
        _check_parent(path, option, "folder")
    return path


def existing_inputs(paths: Mapping[str | os.PathLike[str] | None, str]) -> dict[Path, str]:
    """``paths`` without the ``None`` keys, as :class:`Path` -> what each is."""
    return {Path(p): what for p, what in paths.items() if p is not None}


def _temporary(path: Path) -> Path:
    """A new empty file next to ``path`` with the same suffix (writers may go by it)."""
    try:
        handle, name = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    except OSError as exc:
        raise InputError(
            f"cannot write the output file: {exc.strerror or exc}", file=path, expected="a writable folder"
        ) from None
    os.close(handle)
    return Path(name)


def _mode_for(path: Path) -> int:
    """The permission bits of ``path`` when it exists, else those a new file gets (umask)."""
    if path.is_file():
        return stat.S_IMODE(path.stat().st_mode)
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _flush_to_disk(path: Path) -> None:
    """Make the written bytes of ``path`` durable before it replaces anything (a full disk fails here)."""
    handle = os.open(path, os.O_RDWR)  # Windows commits only handles open for writing
    try:
        os.fsync(handle)
    finally:
        os.close(handle)


def write_atomically(path: str | os.PathLike[str], write: Callable[[Path], _T]) -> _T:
    """Call ``write(temporary)`` with a temporary file in ``path``'s folder, then move it onto
    ``path`` (:func:`os.replace`); returns what ``write`` returned. On any failure the
    temporary file is removed and ``path`` is left as it was. An :class:`OSError` becomes an
    :class:`InputError` naming ``path``."""
    path = Path(path)
    temporary = _temporary(path)
    try:
        result = write(temporary)
        _flush_to_disk(temporary)
        os.chmod(temporary, _mode_for(path))
        os.replace(temporary, path)
        return result
    except BaseException as exc:
        temporary.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise InputError(
                f"cannot write the output file: {exc.strerror or exc}", file=path, expected="a writable folder"
            ) from None
        raise


def write_output(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically (see module docstring); an
    :class:`InputError` naming ``path`` when the folder is not writable."""
    write_atomically(path, lambda temporary: temporary.write_text(text, encoding="utf-8"))


#: prefix of the staging folders of :func:`staged_outputs` (hidden: ``nmsm plot`` and the
#: results-folder searches skip them)
STAGING_PREFIX = ".nmsm-staging-"


class StagedOutputs:
    """The output files of one command, staged next to where they go (:func:`staged_outputs`).

    :meth:`folder` gives a staging folder whose files (and sub-folders) go into a destination
    folder, :meth:`file` where to write one destination file; :meth:`destination` maps a
    staged path back to where it goes.
    """

    def __init__(self) -> None:
        self._stages: dict[Path, Path] = {}  # destination folder -> its staging folder
        self._created: list[Path] = []  # folders this command created, in creation order

    def folder(self, destination: str | os.PathLike[str]) -> Path:
        """The staging folder of ``destination`` (created with ``destination`` when missing)."""
        destination = Path(destination)
        for known, stage in self._stages.items():
            if os.path.abspath(known) == os.path.abspath(destination):
                return stage
        self._make_folder(destination)
        try:
            stage = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=destination))
        except OSError as exc:
            raise InputError(f"cannot write the output folder: {exc.strerror or exc}", file=destination,
                             expected="a writable folder") from None
        self._stages[destination] = stage
        return stage

    def file(self, path: str | os.PathLike[str]) -> Path:
        """Where to write the output file ``path``: in the staging folder of its folder."""
        path = Path(path)
        return self.folder(path.parent) / path.name

    def destination(self, staged: str | os.PathLike[str]) -> Path:
        """Where the staged file ``staged`` goes (``staged`` itself when it is not staged)."""
        staged = Path(staged)
        absolute = Path(os.path.abspath(staged))
        for destination, stage in self._stages.items():
            if absolute.is_relative_to(os.path.abspath(stage)):
                return destination / absolute.relative_to(os.path.abspath(stage))
        return staged

    def _make_folder(self, folder: Path) -> None:
        """Create ``folder`` and its missing parents, remembering them for :meth:`_discard`."""
        self._created += _make_missing_folders(folder)

    def _staged_files(self) -> list[tuple[Path, Path]]:
        """``(staged file, destination)`` of every staged file."""
        return [(src, destination / src.relative_to(stage)) for destination, stage in self._stages.items()
                for src in sorted(stage.rglob("*")) if src.is_file()]

    def _commit(self) -> None:
        """Make every staged file durable, then move them all into place; a failure while
        moving puts the files moved so far back (the earlier files restored)."""
        moves = self._staged_files()
        for src, dest in moves:
            try:
                _flush_to_disk(src)
                os.chmod(src, _mode_for(dest))
            except OSError as exc:
                raise InputError(f"cannot write the output file: {exc.strerror or exc}", file=dest,
                                 expected="a writable folder") from None
        move_into_place(moves)

    def _remove_stages(self) -> None:
        for stage in self._stages.values():
            shutil.rmtree(stage, ignore_errors=True)

    def _discard(self) -> None:
        """Remove the staged files and the folders this command created (when left empty)."""
        self._remove_stages()
        for folder in reversed(self._created):
            with contextlib.suppress(OSError):
                folder.rmdir()
        self._created = []

    def _named(self, exc: OSError) -> OSError | InputError:
        """An :class:`InputError` naming the destination of a staged file that could not be
        written; other errors as they are."""
        if not isinstance(exc.filename, (str, bytes, os.PathLike)):
            return exc
        staged = Path(os.fsdecode(exc.filename))
        where = self.destination(staged)
        if where is staged:
            return exc
        return InputError(f"cannot write the output file: {exc.strerror or exc}", file=where,
                          expected="a writable folder")


def move_into_place(moves: Iterable[tuple[Path, Path]]) -> None:
    """Move each ``(staged file, destination)`` into place, all or none: an earlier file at a
    destination is kept aside until every move succeeded (then deleted); missing destination
    folders are created. A failure or a stop (``KeyboardInterrupt``) while moving puts the
    files moved so far back, the earlier files restored, and removes the folders it created.
    A destination that is a folder is refused before anything moves. An :class:`OSError`
    becomes an :class:`InputError` naming the destination (or folder) that failed."""
    moves = list(moves)
    for _, dest in moves:
        if dest.is_dir() and not dest.is_symlink():
            raise InputError("cannot write the output file: a folder of that name exists", file=dest,
                             expected="a file name that is not a folder")
    done: list[tuple[Path, Path, Path | None]] = []
    created: list[Path] = []
    current = Path()
    try:
        for src, dest in moves:
            current = dest.parent
            created += _make_missing_folders(dest.parent)
            current = dest
            earlier = dest.exists() or dest.is_symlink()
            backup = dest.with_name(f".{dest.name}.nmsm-replaced-{secrets.token_hex(4)}") if earlier else None
            done.append((src, dest, backup))
            if backup is not None:
                os.replace(dest, backup)
            os.replace(src, dest)
    except BaseException as exc:
        _put_back(done)
        for folder in reversed(created):
            with contextlib.suppress(OSError):
                folder.rmdir()
        if isinstance(exc, OSError):
            raise InputError(f"cannot write the output file: {exc.strerror or exc}", file=current,
                             expected="a writable folder") from None
        raise
    for _, _, backup in done:
        if backup is not None:
            with contextlib.suppress(OSError):
                backup.unlink()


def _make_missing_folders(folder: Path) -> list[Path]:
    """Create ``folder`` and its missing parents; returns those created, outermost first."""
    missing = []
    probe = folder
    while not probe.exists() and not probe.is_symlink() and probe != probe.parent:
        missing.append(probe)
        probe = probe.parent
    created: list[Path] = []
    for path in reversed(missing):
        try:
            path.mkdir()
        except FileExistsError:
            continue
        except OSError as exc:
            for folder in reversed(created):
                with contextlib.suppress(OSError):
                    folder.rmdir()
            raise InputError(f"cannot create the output folder: {exc.strerror or exc}", file=path,
                             expected="a writable folder") from None
        created.append(path)
    return created


def _put_back(done: list[tuple[Path, Path, Path | None]]) -> None:
    """Undo the moves of :func:`move_into_place`, last first: each earlier file back
    in place, each new file removed."""
    for src, dest, backup in reversed(done):
        with contextlib.suppress(OSError):
            if backup is not None and backup.exists():
                os.replace(backup, dest)
            elif not (src.exists() or src.is_symlink()):
                dest.unlink(missing_ok=True)


@contextlib.contextmanager
def staged_outputs() -> Iterator[StagedOutputs]:
    """Write several output files all or nothing (module docstring)::

        with staged_outputs() as staged:
            result.write(staged.folder(output_folder), trial)   # files under output_folder
            model.save(staged.file(json_path))                  # one file
        # every file in place now; on any exception none of them is, earlier files unchanged

    An :class:`OSError` writing a staged file becomes an :class:`InputError` naming its
    destination.
    """
    staged = StagedOutputs()
    try:
        yield staged
        staged._commit()
    except BaseException as exc:
        staged._discard()
        if isinstance(exc, OSError):
            named = staged._named(exc)
            if named is not exc:
                raise named from None
        raise
    staged._remove_stages()

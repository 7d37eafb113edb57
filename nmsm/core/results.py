"""Results folders that never hold half-written files and never overwrite inputs.

A tool writes each task's files into a staging folder inside the results directory and
:meth:`ResultsDirectory.task` moves them into place only when the task finished. A stop
or a failure leaves the finished tasks' files and nothing else.

    results = ResultsDirectory(settings.results_directory, inputs=[model_path, trc_path])
    with results.task("knee") as stage:        # stage: pathlib.Path of the staging folder
        write_model(stage / "subject_jmp.osim")
    # files now in results.path

A task given a ``record`` name also lists the files it wrote in a hidden record
(``.nmsm-outputs-<record>.txt``). :meth:`ResultsDirectory.retire` moves the files an earlier
task of that record wrote into ``superseded/`` (and only those: never a user's file or an
input), so a later run that fails leaves nothing from the earlier one looking like its own;
a recorded task that finishes retires the earlier files it did not rewrite.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from nmsm.errors import InputError

#: folder (inside the results folder) that retired files of an earlier run are moved into
SUPERSEDED = "superseded"
_RECORD = ".nmsm-outputs-{}.txt"


def _refuse_read_only(path: Path) -> None:
    """Refuse a folder (or its nearest existing ancestor) without any write permission bit.

    Checked on the mode bits, not with ``os.access``, so a read-only data tree is refused
    even when running as root (who could write anyway).
    """
    probe = path.resolve()
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe.exists() and not (probe.stat().st_mode & 0o222):
        raise InputError(
            f"results folder {path} is inside read-only folder {probe}; nmsm does not write "
            "there (pass another results directory, e.g. nmsm run -o RESULTS_DIR)",
            file=path,
        )


class ResultsDirectory:
    """A results folder with per-task staging.

    ``inputs`` are files that must never be overwritten: moving a result onto one of them
    raises :class:`InputError`.
    """

    def __init__(self, path: str | os.PathLike[str], *, inputs: Iterable[str | os.PathLike[str]] = ()) -> None:
        self.path = Path(path)
        _refuse_read_only(self.path)
        self.path.mkdir(parents=True, exist_ok=True)
        self._inputs = {Path(p).resolve() for p in inputs}

    def protect(self, *paths: str | os.PathLike[str]) -> None:
        """Add input files that results must never replace."""
        self._inputs.update(Path(p).resolve() for p in paths)

    @contextlib.contextmanager
    def task(self, name: str = "task", *, record: str | None = None) -> Iterator[Path]:
        """Stage a task's files; move them into the results folder when the block ends normally.

        ``record``: list the files in that record, retiring those of the earlier record that
        were not written again (module docstring).
        """
        stage = Path(tempfile.mkdtemp(prefix=f".staging-{_safe(name)}-", dir=self.path))
        try:
            yield stage
        except BaseException:
            shutil.rmtree(stage, ignore_errors=True)
            raise
        try:
            written = self._commit(stage)
        finally:
            shutil.rmtree(stage, ignore_errors=True)
        if record is not None:
            again = set(written)
            self._move(record, [p for p in self.recorded(record) if p not in again], SUPERSEDED)
            _write_record(self.path / _RECORD.format(_safe(record)), written)

    def _commit(self, stage: Path) -> list[Path]:
        files = [p for p in sorted(stage.rglob("*")) if p.is_file()]
        for src in files:
            dest = (self.path / src.relative_to(stage)).resolve()
            if dest in self._inputs:
                raise InputError(
                    "a result would overwrite an input file; choose another results_directory "
                    "or output name",
                    file=dest,
                )
        for src in files:
            dest = self.path / src.relative_to(stage)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(src, dest)
        return [src.relative_to(stage) for src in files]

    def recorded(self, record: str, folder: str | None = None) -> list[Path]:
        """Files (relative to the results folder, or to its subfolder ``folder``) that the
        tasks of ``record`` wrote there and that are still there; inputs and paths outside
        the folder are never listed."""
        base = self.path / folder if folder else self.path
        path = base / _RECORD.format(_safe(record))
        if not path.is_file():
            return []
        root = base.resolve()
        found = []
        for line in path.read_text(encoding="utf-8").splitlines():
            relative = Path(line.strip())
            target = (base / relative).resolve()
            if (line.strip() and not relative.is_absolute() and target.is_relative_to(root) and target.is_file()
                    and target not in self._inputs):
                found.append(relative)
        return found

    def retire(self, record: str, into: str = SUPERSEDED) -> list[Path]:
        """Move the files the tasks of ``record`` wrote into ``<results>/<into>/`` (replacing
        what an earlier retire of ``record`` put there); returns the moved files (relative)."""
        moved = self._move(record, self.recorded(record), into)
        (self.path / _RECORD.format(_safe(record))).unlink(missing_ok=True)
        return moved

    def _move(self, record: str, files: list[Path], into: str) -> list[Path]:
        if not files:
            return []
        target = self.path / into
        for old in self.recorded(record, into):
            (target / old).unlink()
            _remove_empty_parents(target / old, target)
        for relative in files:
            dest = target / relative
            if dest.resolve() in self._inputs:
                raise InputError("retiring an earlier result would overwrite an input file", file=dest)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(self.path / relative, dest)
            _remove_empty_parents(self.path / relative, self.path)
        _write_record(target / _RECORD.format(_safe(record)), files)
        return files

    def write_text(self, relative: str, text: str) -> Path:
        """Write one text file atomically (outside a task)."""
        with self.task(Path(relative).stem) as stage:
            target = stage / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text)
        return self.path / relative

    def copy_in(self, source: str | os.PathLike[str], relative: str | None = None) -> Path:
        """Copy a file (e.g. the settings file) into the results folder atomically."""
        source = Path(source)
        relative = relative or source.name
        with self.task(Path(relative).stem) as stage:
            target = stage / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
        return self.path / relative


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)[:40]


def _write_record(path: Path, files: Iterable[Path]) -> None:
    temporary = path.with_name(path.name + ".tmp")
    temporary.write_text("".join(f"{Path(f).as_posix()}\n" for f in files), encoding="utf-8")
    os.replace(temporary, path)


def _remove_empty_parents(path: Path, root: Path) -> None:
    """Remove the folders between ``path`` and ``root`` that became empty."""
    folder = path.parent
    while folder != root and folder.is_relative_to(root):
        try:
            folder.rmdir()
        except OSError:
            return
        folder = folder.parent

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

A whole run can keep one record instead (``ResultsDirectory(..., record="mtp")``, the
personalization tools): when the run's first task finishes, the files the tool's earlier run
wrote there move into ``superseded/``, and any other file a result replaces (a user's file, an
earlier tool's or program's result of the same name) is moved there too, with a warning, so
a rerun never mixes with an earlier run's files and never deletes a file it did not write.

A task's files are moved in all or none (:func:`nmsm.io.output_file.move_into_place`): a
failure or a stop while moving puts back the files moved so far and the earlier files they
replace in place, and removes the folders it created. (Files a recorded run has already moved
into ``superseded/`` before that, the earlier run's and the replaced ones, stay there.)

A run stopped after some of its tasks (MTP, GCP: each task refines one result) writes the
results after its last finished task with :meth:`ResultsDirectory.stopped_task` into
``stopped_after_task_<k>/``: the earlier complete run's files stay where they are; the next
run that finishes a task retires that folder into ``superseded/`` with the earlier run's files.

The folder is created when the first task starts, and removed again if that task fails and
leaves it empty, so a run refused for bad input leaves no empty results folder behind.
Results folders equal to or inside an input folder (``input_folders``) are refused at
construction, before anything is solved or written.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import warnings
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path

from nmsm.core.unconverged_stamp import stamp_unconverged
from nmsm.errors import InputError
from nmsm.io.output_file import move_into_place

#: folder (inside the results folder) that retired files of an earlier run are moved into
SUPERSEDED = "superseded"
#: folder of the results after the last finished task of a stopped run (``{k}``: that task)
STOPPED_FOLDER = "stopped_after_task_{k}"
_RECORD = ".nmsm-outputs-{}.txt"


def _refuse_read_only(path: Path) -> None:
    """Refuse a folder (or its nearest existing ancestor) without any write permission bit.

    Checked on the mode bits as well as with ``os.access``, so a read-only data tree is
    refused even when running as root (who could write anyway).
    """
    probe = path.resolve()
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise InputError(f"cannot create the results folder {path}: {probe} is a file, not a folder", file=path,
                         expected="a folder (or a path where one can be created)")
    if probe.exists() and (not (probe.stat().st_mode & 0o222) or not os.access(probe, os.W_OK | os.X_OK)):
        raise InputError(
            f"results folder {path} is inside read-only folder {probe}; nmsm does not write "
            "there (pass another results directory, e.g. nmsm run -o RESULTS_DIR)",
            file=path,
        )


def _refuse_input_folders(path: Path, folders: Mapping[str, str | os.PathLike[str]],
                          roots: Mapping[str, str | os.PathLike[str]],
                          settings_file: str | os.PathLike[str] | None) -> None:
    """Refuse a results folder that is, or is inside, one of the input ``folders``, or that is
    one of the ``roots`` (description -> folder): results there would mix with the data they
    are computed from (and a trial folder would list them as trials on the next run)."""
    target = path.resolve()
    checks = [(what, Path(f).resolve(), True) for what, f in folders.items()]
    checks += [(what, Path(f).resolve(), False) for what, f in roots.items()]
    for what, folder, inside in checks:
        if target == folder or (inside and target.is_relative_to(folder)):
            where = "is" if target == folder else "is inside"
            raise InputError(
                f"the results folder {path} {where} the {what} folder {folder}: the results would mix with "
                "the files they are computed from",
                file=settings_file if settings_file is not None else path,
                element="<results_directory>" if settings_file is not None else None,
                expected="a results folder apart from the input folders (e.g. nmsm run -o RESULTS_DIR)",
            )


class ResultsDirectory:
    """A results folder with per-task staging.

    ``inputs`` are files that must never be overwritten: moving a result onto one of them
    raises :class:`InputError`. ``input_folders`` (description -> folder) are folders the
    results folder must not be or be inside, ``input_roots`` folders it must not be (it may
    be a new sub-folder of one; both refused here, before any work; see
    :mod:`nmsm.io.layout`). ``record``: the run's record (module docstring).
    ``settings_file``: named in the refusals.
    """

    def __init__(self, path: str | os.PathLike[str], *, inputs: Iterable[str | os.PathLike[str]] = (),
                 input_folders: Mapping[str, str | os.PathLike[str]] | None = None,
                 input_roots: Mapping[str, str | os.PathLike[str]] | None = None, record: str | None = None,
                 settings_file: str | os.PathLike[str] | None = None) -> None:
        self.path = Path(path)
        _refuse_read_only(self.path)
        _refuse_input_folders(self.path, input_folders or {}, input_roots or {}, settings_file)
        self._inputs = {Path(p).resolve() for p in inputs}
        self._record = record
        self._run_files: list[Path] = []
        self._begun = False
        self._created: list[Path] = []

    def ensure(self) -> Path:
        """Create the results folder (and missing parents) if needed; returns it."""
        missing = []
        probe = self.path
        while not probe.exists() and probe != probe.parent:
            missing.append(probe)
            probe = probe.parent
        self.path.mkdir(parents=True, exist_ok=True)
        self._created.extend(m for m in missing if m not in self._created)
        return self.path

    def reserve(self, *relative: str | os.PathLike[str], element: str | None = None) -> None:
        """Refuse now (before solving) outputs whose names are already known if one would
        replace an input file."""
        for name in relative:
            dest = (self.path / name).resolve()
            if dest in self._inputs:
                raise InputError(
                    f"the result {Path(name).name} would overwrite an input file",
                    file=dest, element=element,
                    expected="another results folder or output name",
                )

    def remove_if_unused(self) -> None:
        """Remove the folders :meth:`ensure` created while they are still empty (none once a
        task finished): for a run that used the folder outside a task and then stopped."""
        for folder in self._created:
            try:
                folder.rmdir()
            except OSError:
                return
        self._created = []

    def protect(self, *paths: str | os.PathLike[str]) -> None:
        """Add input files that results must never replace."""
        self._inputs.update(Path(p).resolve() for p in paths)

    @contextlib.contextmanager
    def task(self, name: str = "task", *, record: str | None = None, part_of_run: bool = True,
             unconverged: str | None = None) -> Iterator[Path]:
        """Stage a task's files; move them into the results folder when the block ends normally.

        ``record``: list the files in that record, retiring those of the earlier record that
        were not written again (module docstring). ``part_of_run`` False: the run's record
        (``ResultsDirectory(record=...)``) is neither begun nor extended by this task.
        ``unconverged``: the note of accepted unconverged results; every staged file is
        stamped with it before the move (:func:`nmsm.core.unconverged_stamp.stamp_unconverged`).
        """
        stage = Path(tempfile.mkdtemp(prefix=f".staging-{_safe(name)}-", dir=self.ensure()))
        try:
            yield stage
        except BaseException as exc:
            shutil.rmtree(stage, ignore_errors=True)
            self.remove_if_unused()
            if isinstance(exc, OSError) and exc.filename is None:  # e.g. a full disk while writing: name the folder
                exc.filename = str(self.path)
            raise
        try:
            if unconverged is not None:
                stamp_unconverged(stage, unconverged)
            written = self._commit(stage, part_of_run)
        except BaseException:
            self.remove_if_unused()
            raise
        finally:
            shutil.rmtree(stage, ignore_errors=True)
        self._created = []
        if self._record is not None and part_of_run:
            self._run_files.extend(p for p in written if p not in self._run_files)
            _write_record(self.path / _RECORD.format(_safe(self._record)), self._run_files)
        if record is not None:
            again = set(written)
            self._move(record, [p for p in self.recorded(record) if p not in again], SUPERSEDED)
            _write_record(self.path / _RECORD.format(_safe(record)), written)

    @contextlib.contextmanager
    def stopped_task(self, last_finished: int) -> Iterator[Path]:
        """Stage the results after task ``last_finished`` of a stopped run into
        ``<results>/stopped_after_task_<k>/`` (yields that folder inside the staging folder;
        module docstring). Needs the run's record."""
        if self._record is None:
            raise ValueError("stopped_task needs ResultsDirectory(record=...)")
        with self.task("stopped", record=_stopped_record(self._record), part_of_run=False) as stage:
            folder = stage / STOPPED_FOLDER.format(k=last_finished)
            folder.mkdir()
            yield folder

    def _commit(self, stage: Path, part_of_run: bool = True) -> list[Path]:
        files = [p for p in sorted(stage.rglob("*")) if p.is_file()]
        for src in files:
            dest = (self.path / src.relative_to(stage)).resolve()
            if dest in self._inputs:
                raise InputError(
                    f"the result {src.name} would overwrite an input file; choose another results_directory "
                    "or output name",
                    file=dest,
                )
        if self._record is not None and part_of_run:
            self._begin_run()
            self._set_aside([src.relative_to(stage) for src in files])
        move_into_place([(src, self.path / src.relative_to(stage)) for src in files])
        return [src.relative_to(stage) for src in files]

    def _begin_run(self) -> None:
        """First commit of a recorded run: retire the tool's earlier run's files."""
        if self._begun:
            return
        self._begun = True
        moved = self.retire(self._record) + self.retire(_stopped_record(self._record))
        if moved:
            warnings.warn(f"{self.path}: the {len(moved)} files of the earlier {self._record} run there were moved "
                          f"to {self.path / SUPERSEDED}", stacklevel=4)

    def _set_aside(self, relative: list[Path]) -> None:
        """Move existing files that results will replace and that this run did not write
        (a user's or another program's) into ``superseded/``, with a warning."""
        ours = set(self._run_files)
        taken = [r for r in relative if r not in ours and (self.path / r).is_file()]
        if not taken:
            return
        aside = f"{SUPERSEDED}/replaced"
        for r in taken:
            dest = self.path / aside / r
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(self.path / r, dest)
        names = ", ".join(r.as_posix() for r in taken[:3]) + (", ..." if len(taken) > 3 else "")
        warnings.warn(f"{self.path}: {len(taken)} existing files that this {self._record} run replaces ({names}) "
                      f"were not written by it; moved to {self.path / aside}", stacklevel=5)

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

    def write_text(self, relative: str, text: str, *, unconverged: str | None = None) -> Path:
        """Write one text file atomically (outside a task)."""
        with self.task(Path(relative).stem, unconverged=unconverged) as stage:
            target = stage / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text, encoding="utf-8")
        return self.path / relative

    def copy_in(self, source: str | os.PathLike[str], relative: str | None = None) -> Path:
        """Copy a file (e.g. the settings file) into the results folder atomically; nothing to
        do when that file is the source itself (a results folder holding the settings)."""
        source = Path(source)
        relative = relative or source.name
        if (self.path / relative).resolve() == source.resolve():
            return self.path / relative
        with self.task(Path(relative).stem) as stage:
            target = stage / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)
        return self.path / relative


def _stopped_record(record: str) -> str:
    """The record of a stopped run's :meth:`ResultsDirectory.stopped_task` files."""
    return f"{record}-stopped"


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

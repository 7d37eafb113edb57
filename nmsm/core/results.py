"""Results folders that never hold half-written files and never overwrite inputs.

A tool writes each task's files into a staging folder inside the results directory and
:meth:`ResultsDirectory.task` moves them into place only when the task finished. A stop
or a failure leaves the finished tasks' files and nothing else.

    results = ResultsDirectory(settings.results_directory, inputs=[model_path, trc_path])
    with results.task("knee") as stage:        # stage: pathlib.Path of the staging folder
        write_model(stage / "subject_jmp.osim")
    # files now in results.path
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path

from nmsm.errors import InputError


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
    def task(self, name: str = "task") -> Iterator[Path]:
        """Stage a task's files; move them into the results folder when the block ends normally."""
        safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in name)[:40]
        stage = Path(tempfile.mkdtemp(prefix=f".staging-{safe}-", dir=self.path))
        try:
            yield stage
        except BaseException:
            shutil.rmtree(stage, ignore_errors=True)
            raise
        try:
            self._commit(stage)
        finally:
            shutil.rmtree(stage, ignore_errors=True)

    def _commit(self, stage: Path) -> None:
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

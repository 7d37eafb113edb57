"""The pipeline's record of finished stages: ``<results_directory>/pipeline_state.json``.

One record per finished stage, written (atomically, by replacing the file) only after the
stage's tool returned and its outputs were found::

    {"format": "nmsm-pipeline-state", "version": 1, "nmsm_version": "0.1.0",
     "stages": {"mtp": {"kind": "mtp", "tool": "MuscleTendonPersonalizationTool",
                        "settings_file": "mtp.xml", "results_directory": "mtp",
                        "input_digest": "<sha256>", "outputs": {"osimx": "mtp/model_mtp.osimx", ...},
                        "output_digest": "<sha256>", "finished": "2025-01-01T12:00:00",
                        "wall_time": 12.5}},
     "stage_folders": {"mtp": "mtp"}}

Paths in records are relative to the results directory (the tree can be moved). A stage
stopped half-way has no record, so the next run redoes it and nothing after it.
``stage_folders`` lists the stage folders the runner created (saved before the stage's tool
runs): the runner empties only those (or a folder of a recorded stage), never a folder it
did not write. A file without it (older nmsm) reads as none created.

A file of another format version, or a record missing a field, is an
:class:`~nmsm.errors.InputError` naming the file, the stage and the missing piece.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any

import attrs

from nmsm.errors import InputError

STATE_FILE = "pipeline_state.json"
FORMAT = "nmsm-pipeline-state"
#: version of the results-tree layout and of this file; bump when either changes
VERSION = 1
_RECORD_FIELDS = ("kind", "tool", "settings_file", "results_directory", "input_digest", "outputs",
                  "output_digest", "finished", "wall_time")


@attrs.frozen
class StageRecord:
    """A finished stage: what it read (digest), what it wrote (outputs, digest), when."""

    name: str
    kind: str
    tool: str
    settings_file: str  #: relative to the results directory
    results_directory: str  #: relative to the results directory
    input_digest: str
    outputs: dict[str, str]  #: artifact -> path relative to the results directory
    output_digest: str
    finished: str  #: ISO time
    wall_time: float  #: s

    def to_json(self) -> dict[str, Any]:
        data = attrs.asdict(self)
        del data["name"]
        return data


def _stale_error(path: Path, message: str, expected: str) -> InputError:
    return InputError(
        message + "; delete the results folder or choose another <results_directory> "
        "(or run 'nmsm pipeline --rebuild' to redo every stage)",
        file=path,
        expected=expected,
    )


class PipelineState:
    """The records of a results directory; :meth:`save` rewrites the file atomically."""

    def __init__(self, results_directory: Path, records: dict[str, StageRecord] | None = None,
                 nmsm_version: str = "", folders: dict[str, str] | None = None) -> None:
        self.results_directory = Path(results_directory)
        self.records: dict[str, StageRecord] = dict(records or {})
        self.nmsm_version = nmsm_version
        #: stage name -> folder (relative to the results directory) the runner created for it
        self.folders: dict[str, str] = dict(folders or {})

    @property
    def path(self) -> Path:
        return self.results_directory / STATE_FILE

    # ---- reading -----------------------------------------------------------------------
    @classmethod
    def load(cls, results_directory: str | os.PathLike[str]) -> PipelineState:
        """The records of ``results_directory`` (none when the file does not exist yet)."""
        results_directory = Path(results_directory)
        path = results_directory / STATE_FILE
        if not path.is_file():
            return cls(results_directory)
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError) as exc:
            raise _stale_error(path, f"unreadable pipeline state ({exc})", f"a JSON file of format '{FORMAT}'") from None
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise _stale_error(path, "not a pipeline state file", f"\"format\": \"{FORMAT}\"")
        version = data.get("version")
        if version != VERSION:
            age = "an older" if isinstance(version, int) and version < VERSION else "another"
            raise _stale_error(
                path,
                f"results tree written by {age} nmsm pipeline (state format version {version}, "
                f"nmsm {data.get('nmsm_version', 'unknown')})",
                f"state format version {VERSION}",
            )
        stages = data.get("stages")
        if not isinstance(stages, dict):
            raise _stale_error(path, "no \"stages\" table", "a \"stages\" object")
        records: dict[str, StageRecord] = {}
        for name, raw in stages.items():
            missing = [f for f in _RECORD_FIELDS if not isinstance(raw, dict) or f not in raw]
            if missing:
                raise _stale_error(path, f"stage '{name}': record lacks {', '.join(missing)}",
                                   "every stage record with " + ", ".join(_RECORD_FIELDS))
            records[name] = StageRecord(name=name, **{f: raw[f] for f in _RECORD_FIELDS})
        folders = data.get("stage_folders", {})
        if not isinstance(folders, dict) or not all(isinstance(v, str) for v in folders.values()):
            raise _stale_error(path, "\"stage_folders\" is not a table of folder names",
                               "a \"stage_folders\" object of stage name: folder")
        return cls(results_directory, records, str(data.get("nmsm_version", "")), folders)

    def owns(self, name: str, folder: str) -> bool:
        """Whether the runner created ``folder`` (relative) for stage ``name`` or recorded it."""
        record = self.records.get(name)
        return self.folders.get(name) == folder or (record is not None and record.results_directory == folder)

    # ---- writing -----------------------------------------------------------------------
    def record(self, record: StageRecord) -> None:
        """Store a finished stage and save the file."""
        self.records[record.name] = record
        self.save()

    def forget(self, name: str) -> None:
        """Drop a stage's record (before it runs again) and save the file."""
        if self.records.pop(name, None) is not None:
            self.save()

    def claim(self, name: str, folder: str) -> None:
        """Note that the runner created ``folder`` (relative) for stage ``name``; save the file."""
        self.folders[name] = folder
        self.save()

    def save(self) -> None:
        from nmsm import __version__

        self.results_directory.mkdir(parents=True, exist_ok=True)
        data = {
            "format": FORMAT,
            "version": VERSION,
            "nmsm_version": __version__,
            "stages": {name: rec.to_json() for name, rec in self.records.items()},
            "stage_folders": dict(self.folders),
        }
        handle, temporary = tempfile.mkstemp(prefix=".state-", dir=self.results_directory)
        try:
            with os.fdopen(handle, "w") as out:
                json.dump(data, out, indent=2)
                out.write("\n")
            os.replace(temporary, self.path)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise

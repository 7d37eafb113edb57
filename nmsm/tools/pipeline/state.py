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
did not write. A file without it (older nmsm) reads as none created. Each folder it
creates also holds the runner's marker :data:`MARKER` (``{"format": "nmsm-pipeline-stage",
"stage": NAME}``), so that ``--rebuild`` knows its folders when this file is damaged.

A damaged file (not JSON, another format version, a record missing a field) is an
:class:`~nmsm.errors.InputError` naming the file, the stage and the missing piece, unless
it is loaded with ``salvage=True`` (``--rebuild``, which redoes every stage anyway): then
the records are dropped, the folders it still names are kept (when the JSON is readable),
and the damaged file is moved to ``pipeline_state.json.damaged`` when the state is saved.
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
#: where a damaged state file is moved when ``--rebuild`` saves a new one
DAMAGED_SUFFIX = ".damaged"
#: the runner's marker in every stage folder it creates (hidden: left out of output digests)
MARKER = ".nmsm-pipeline-stage"
MARKER_FORMAT = "nmsm-pipeline-stage"
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
    error = InputError(
        message + "; run 'nmsm pipeline --rebuild PIPELINE.xml' to redo every stage (it empties only the stage "
        f"folders this file still names or that hold the runner's {MARKER} marker; any other stage folder must "
        "be moved away by hand), or delete the results folder or choose another <results_directory>",
        file=path,
        expected=expected,
    )
    error.reason = message  # type: ignore[attr-defined]
    return error


def write_marker(folder: Path, name: str) -> None:
    """Mark ``folder`` as created by the runner for stage ``name``."""
    (folder / MARKER).write_text(json.dumps({"format": MARKER_FORMAT, "stage": name}) + "\n", encoding="utf-8")


def has_marker(folder: Path, name: str) -> bool:
    """Whether ``folder`` holds the runner's marker for stage ``name`` (a regular file)."""
    marker = folder / MARKER
    if marker.is_symlink() or not marker.is_file():
        return False
    try:
        data = json.loads(marker.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("format") == MARKER_FORMAT and data.get("stage") == name


class PipelineState:
    """The records of a results directory; :meth:`save` rewrites the file atomically."""

    def __init__(self, results_directory: Path, records: dict[str, StageRecord] | None = None,
                 nmsm_version: str = "", folders: dict[str, str] | None = None) -> None:
        self.results_directory = Path(results_directory)
        self.records: dict[str, StageRecord] = dict(records or {})
        self.nmsm_version = nmsm_version
        #: stage name -> folder (relative to the results directory) the runner created for it
        self.folders: dict[str, str] = dict(folders or {})
        #: why the file was not usable (loaded with ``salvage=True``); ``None``: it was
        self.damaged: str | None = None

    @property
    def path(self) -> Path:
        return self.results_directory / STATE_FILE

    # ---- reading -----------------------------------------------------------------------
    @classmethod
    def load(cls, results_directory: str | os.PathLike[str], *, salvage: bool = False) -> PipelineState:
        """The records of ``results_directory`` (none when the file does not exist yet).

        ``salvage``: a damaged file gives a state without records that keeps the folders
        the file still names (module docstring) instead of an error."""
        results_directory = Path(results_directory)
        try:
            return cls._load(results_directory)
        except InputError as exc:
            if not salvage:
                raise
            state = cls(results_directory, folders=_salvage_folders(results_directory / STATE_FILE))
            state.damaged = getattr(exc, "reason", exc.detail)
            return state

    @classmethod
    def _load(cls, results_directory: Path) -> PipelineState:
        path = results_directory / STATE_FILE
        if not path.is_file():
            return cls(results_directory)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
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
        from nmsm.version import __version__

        self.results_directory.mkdir(parents=True, exist_ok=True)
        if self.damaged is not None and self.path.is_file():
            os.replace(self.path, self.path.with_name(STATE_FILE + DAMAGED_SUFFIX))  # kept for inspection
        self.damaged = None
        data = {
            "format": FORMAT,
            "version": VERSION,
            "nmsm_version": __version__,
            "stages": {name: rec.to_json() for name, rec in self.records.items()},
            "stage_folders": dict(self.folders),
        }
        handle, temporary = tempfile.mkstemp(prefix=".state-", dir=self.results_directory)
        try:
            with os.fdopen(handle, "w", encoding="utf-8") as out:
                json.dump(data, out, indent=2)
                out.write("\n")
            os.replace(temporary, self.path)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise


def _salvage_folders(path: Path) -> dict[str, str]:
    """Stage name -> folder that a damaged but readable state file still names: its
    ``stage_folders`` and its records' ``results_directory`` (empty when it is not JSON of
    this format)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        return {}
    folders: dict[str, str] = {}
    stages = data.get("stages")
    for name, raw in (stages.items() if isinstance(stages, dict) else ()):
        if isinstance(raw, dict) and isinstance(raw.get("results_directory"), str):
            folders[str(name)] = raw["results_directory"]
    listed = data.get("stage_folders")
    for name, folder in (listed.items() if isinstance(listed, dict) else ()):
        if isinstance(folder, str):
            folders[str(name)] = folder
    return folders

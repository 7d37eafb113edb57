"""Read a treatment problem's data folders (docs/treatment.md).

``tracked_quantities_directory``: ``IKData/<trial>`` (required), ``IDData/<trial>``,
``GRFData/<trial>`` (optional). ``initial_guess_directory``: optional ``IKData``/``IDData``
and the files a previous TO/VO/DO wrote: ``<trial>_states.sto`` (``q``, ``q_u`` columns),
``<trial>_accelerations.sto``, ``<trial>_torqueControls.sto``, ``<trial>_synergyCommands.sto``,
``<trial>_combinedActivations.sto``, ``<trial>_muscleExcitations.sto`` (muscle controller with
activation dynamics) and ``synergyWeights.sto``. Tracked data come from the
tracked folder, the initial kinematics from the initial-guess folder (falling back to the
tracked ones). Times are shifted to start at 0 (each file's start is kept in
``TreatmentFiles.start_times``); IK degrees become radians for the model's rotational
coordinates only. :func:`guess_time_problems` reports initial-guess files on other times than
the tracked data. The tracked ID and GRF files must start with the tracked IK (each is read
from its own start, so one starting elsewhere would be tracked shifted in time) and last at
least as long (a longer file is fine: only its first part is used); frames more than 0.5 s
apart over more than 30 s are taken for times in milliseconds (a coarse collocation mesh of a
short motion is not): :class:`InputError` otherwise.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.motion_units import warn_implausible_angles
from nmsm.io.storage import COP_SUFFIXES, Table, read_storage
from nmsm.io.trials import find_trial_file
from nmsm.core.ocp_model import TreatmentModel

#: largest sample interval (s) of a tracked IK longer than MILLISECOND_DURATION (s): more is
#: taken for times in milliseconds (a 0.3 s kick in ms lasts "300 s" with "5 s" frames)
LONGEST_SAMPLE_INTERVAL = 0.5
MILLISECOND_DURATION = 30.0

#: initial-guess files written by a previous TO/VO/DO: kind -> file suffix
RESULT_FILES = {
    "states": "_states",
    "accelerations": "_accelerations",
    "torqueControls": "_torqueControls",
    "synergyCommands": "_synergyCommands",
    "combinedActivations": "_combinedActivations",
    "muscleExcitations": "_muscleExcitations",
}


@attrs.define
class TreatmentFiles:
    """Tables of one trial (time from 0; kinematics in radians)."""

    trial: str
    tracked_ik: Table
    tracked_id: Table | None
    tracked_grf: Table | None
    initial_ik: Table
    initial_id: Table | None
    results: dict[str, Table]
    synergy_weights: Table | None
    tracked_directory: Path
    initial_directory: Path
    #: first time (s) of each file as written, by file path (tables are shifted to start at 0)
    start_times: dict[str, float] = attrs.field(factory=dict)

    def time_range(self, table: Table) -> tuple[float, float]:
        """``(start, end)`` of ``table`` in its file's time (s), before the shift to 0."""
        start = self.start_times.get(str(table.source), 0.0)
        return start, start + duration(table)


def _shift(table: Table, starts: dict[str, float] | None = None) -> Table:
    if starts is not None and table.source is not None:
        starts[str(table.source)] = float(table.time[0])
    return attrs.evolve(table, time=table.time - table.time[0])


def _optional_trial_table(folder: Path, trial: str, starts: dict[str, float] | None = None,
                          **kwargs) -> Table | None:
    if not folder.is_dir():
        return None
    try:
        path = find_trial_file(folder, trial)
    except InputError:
        return None
    return _shift(read_storage(path, **kwargs), starts)


def _kinematics(table: Table, model: TreatmentModel, *, positions: bool = True) -> Table:
    """``table``'s rotational coordinates in radians; for a table of positions (IK, states) a
    header whose unit looks wrong warns (:mod:`nmsm.io.motion_units`)."""
    rotational = {c for c in model.coordinate_names if model.is_rotational(c)}
    if positions:
        warn_implausible_angles(table, rotational)
    return table.to_radians(rotational)


def _result_file(folder: Path, trial: str, suffix: str) -> Path | None:
    exact = folder / f"{trial}{suffix}.sto"
    if exact.is_file():
        return exact
    found = sorted(p for p in folder.glob(f"*{suffix}.sto") if trial in p.name)
    if len(found) > 1:
        raise InputError(f"several '{suffix}' files for trial '{trial}': {', '.join(p.name for p in found)}",
                         file=folder, expected=f"one file named {trial}{suffix}.sto")
    return found[0] if found else None


def read_treatment_files(tracked_dir: Path, initial_dir: Path, trial: str, model: TreatmentModel, *,
                         settings_file: Path | None = None) -> TreatmentFiles:
    """Read the tables of ``trial`` (see module docstring)."""
    tracked_dir, initial_dir = Path(tracked_dir), Path(initial_dir)
    for folder, element in ((tracked_dir, "<tracked_quantities_directory>"), (initial_dir, "<initial_guess_directory>")):
        if not folder.is_dir():
            raise InputError(f"folder not found: {folder}", file=settings_file, element=element,
                             expected="an existing folder")
    ik_folder = tracked_dir / "IKData"
    if not ik_folder.is_dir():
        raise InputError(f"no IKData folder in the tracked quantities directory {tracked_dir}", file=settings_file,
                         element="<tracked_quantities_directory>", expected="a folder holding IKData/<trial>.sto")
    starts: dict[str, float] = {}
    tracked_ik = _kinematics(_shift(read_storage(find_trial_file(ik_folder, trial)), starts), model)
    tracked_id = _optional_trial_table(tracked_dir / "IDData", trial, starts)
    tracked_grf = _optional_trial_table(tracked_dir / "GRFData", trial, starts,
                                        allow_nan=lambda label: label.endswith(COP_SUFFIXES))
    initial_ik = _optional_trial_table(initial_dir / "IKData", trial, starts)
    initial_ik = _kinematics(initial_ik, model) if initial_ik is not None else tracked_ik
    initial_id = _optional_trial_table(initial_dir / "IDData", trial, starts)
    if initial_id is None:
        initial_id = tracked_id
    results: dict[str, Table] = {}
    if initial_dir.is_dir():
        for kind, suffix in RESULT_FILES.items():
            path = _result_file(initial_dir, trial, suffix)
            if path is not None:
                table = _shift(read_storage(path), starts)
                if kind in ("states", "accelerations") and table.in_degrees:
                    table = _kinematics(table, model, positions=kind == "states")
                results[kind] = table
    weights_path = initial_dir / "synergyWeights.sto"
    synergy_weights = read_storage(weights_path) if weights_path.is_file() else None
    for name, table in (("tracked IK", tracked_ik), ("initial IK", initial_ik)):
        if table.n_rows < 2:
            raise InputError(f"{name} has {table.n_rows} row(s)", file=table.source, expected="at least 2 time rows")
    _check_tracked_times(tracked_ik, (tracked_id, tracked_grf), starts)
    if tracked_id is None:
        warnings.warn(f"{tracked_dir}: no IDData/{trial}: terms and torque controls needing tracked loads will fail",
                      stacklevel=2)
    return TreatmentFiles(trial, tracked_ik, tracked_id, tracked_grf, initial_ik, initial_id, results, synergy_weights,
                          tracked_dir, initial_dir, starts)


def _check_tracked_times(ik: Table, others: tuple[Table | None, ...], starts: dict[str, float]) -> None:
    """The tracked IK's frames in seconds, and the tracked ID/GRF files over the same times
    (within one IK sample interval; module docstring)."""
    step = float(np.median(np.diff(ik.time)))
    if step > LONGEST_SAMPLE_INTERVAL and duration(ik) > MILLISECOND_DURATION:
        raise InputError(f"the tracked IK's frames are {step:.6g} s apart over {duration(ik):.6g} s: are the times "
                         "in milliseconds?", file=ik.source, element="column 'time'",
                         expected=f"times in seconds (frames at most {LONGEST_SAMPLE_INTERVAL} s apart, or a "
                         f"motion shorter than {MILLISECOND_DURATION:g} s)")
    start = starts.get(str(ik.source), 0.0)
    end = start + duration(ik)
    for table in others:
        if table is None:
            continue
        first = starts.get(str(table.source), 0.0)
        last = first + duration(table)
        if abs(first - start) > step + 1e-9 or last < end - step - 1e-9:
            kind = table.source.parent.name if table.source is not None else "tracked"
            raise InputError(
                f"the tracked {kind} file covers {first:.6g}-{last:.6g} s but the tracked IK {ik.source} covers "
                f"{start:.6g}-{end:.6g} s",
                file=table.source, element="column 'time'",
                expected=f"a file starting with the tracked IK (within one sample interval, {step:.6g} s) and lasting "
                "at least as long: each file is read from its own start, so one starting elsewhere would be tracked "
                "shifted in time, and one ending earlier does not cover the motion",
            )


def duration(table: Table) -> float:
    return float(np.asarray(table.time)[-1] - np.asarray(table.time)[0])


def _sample_interval(table: Table) -> float:
    """Largest time step of ``table`` (s)."""
    return float(np.max(np.diff(np.asarray(table.time)))) if table.n_rows > 1 else 0.0


def guess_tables(files: TreatmentFiles) -> list[Table]:
    """The initial-guess tables of ``files`` (its initial-guess folder's files, not the tracked ones)."""
    tables = list(files.results.values())
    if files.initial_id is not None and files.initial_id is not files.tracked_id:
        tables.insert(0, files.initial_id)
    if files.initial_ik is not files.tracked_ik:
        tables.insert(0, files.initial_ik)
    return tables


def guess_time_problems(files: TreatmentFiles, read_duration: float) -> list[str]:
    """Initial-guess files that do not span the time they are read on (one line per time range).

    The guess is read from its own start for ``read_duration`` seconds (the tracked data's
    duration with a fixed final time; the guess's with a free one), on the same normalized
    time as the tracked data. A file matches when its duration is ``read_duration`` and it
    starts where the tracked data start (or at 0: nmsm writes results from 0), each within
    one sample interval (the larger of the file's and the tracked data's).
    """
    tracked_start = files.time_range(files.tracked_ik)[0]
    wrong: dict[tuple[float, float], list[Table]] = {}
    tolerance = 0.0
    for table in guess_tables(files):
        start, end = files.time_range(table)
        allowed = max(_sample_interval(table), _sample_interval(files.tracked_ik)) + 1e-9
        if abs(end - start - read_duration) <= allowed and min(abs(start - tracked_start), abs(start)) <= allowed:
            continue
        tolerance = max(tolerance, allowed)
        wrong.setdefault((start, end), []).append(table)
    out = []
    for (start, end), tables in wrong.items():
        names = ", ".join(_relative(t.source, files.initial_directory) for t in tables)
        out.append(f"initial guess {names} in {files.initial_directory} spans {start:.6g}-{end:.6g} s "
                   f"({end - start:.6g} s); expected {tracked_start:.6g}-{tracked_start + read_duration:.6g} s "
                   f"({read_duration:.6g} s, the time range of the tracked data {files.tracked_ik.source}) within "
                   f"one sample interval ({tolerance:.2g} s)")
    return out


def _relative(path: Path | None, folder: Path) -> str:
    if path is None:
        return "(a table without file)"
    try:
        return Path(path).relative_to(folder).as_posix()
    except ValueError:
        return str(path)

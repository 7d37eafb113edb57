"""MTP input data: trials read from the personalization folder layout.

Layout (docs/guide.md, section 2)::

    <data_directory>/IDData/<prefix>.sto          inverse-dynamics loads (N m), 101 rows typical
                     EMGData/<prefix>.sto         processed EMG, rows + 2 * padding
                     MAData/<prefix>/<prefix>_Length.sto, _Velocity.sto,
                                     _MomentArm_<coordinate>.sto

Arrays keep time on axis 0: lengths ``(n_frames, n_muscles)`` (m), velocities (m/s),
moment arms ``(n_frames, n_coordinates, n_muscles)`` (m), moments
``(n_frames, n_coordinates)`` (N m), EMG ``(n_emg_frames, n_channels)`` (-).
"""

from __future__ import annotations

import contextlib
import os
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage
from nmsm.io.trials import find_file_by_suffix, find_trial_file, find_trial_folder, trial_prefixes


@attrs.frozen(eq=False)
class TrialData:
    """One trial's data for MTP (and for NCP without EMG).

    ``time`` (n,) s of the ID/MA rows; ``emg_time`` (n + 2 pad,) s; ``padding`` = EMG frames
    before and after the ID window.
    """

    name: str
    time: np.ndarray
    muscle_tendon_length: np.ndarray
    muscle_tendon_velocity: np.ndarray
    moment_arms: np.ndarray
    inverse_dynamics_moments: np.ndarray
    emg_time: np.ndarray | None = None
    emg: np.ndarray | None = None
    padding: int = 0

    @property
    def n_frames(self) -> int:
        return int(self.time.shape[0])

    @property
    def emg_time_step(self) -> float:
        """Mean EMG sample interval (s), as MATLAB's ``mean(diff(emgTime))``."""
        assert self.emg_time is not None
        return float(np.mean(np.diff(self.emg_time)))


def _columns(table: Table, labels: Sequence[str], what: str) -> np.ndarray:
    missing = [label for label in labels if not table.has(label)]
    if missing:
        raise InputError(
            f"{what} has no column for {', '.join(missing)}",
            file=table.source,
            element=f"column '{missing[0]}'",
            expected=f"one column per muscle/channel: {', '.join(labels)}",
        )
    return table.columns(labels)


def check_same_times(reference: Table, other: Table, prefix: str, *, padding: int = 0) -> None:
    """An :class:`InputError` unless ``other``'s rows ``padding .. padding + n`` lie at the times of
    ``reference`` (the trial's ID file), within a quarter of its median sample interval.

    MTP and NCP match the ID, muscle-analysis and EMG rows by position (as the original), so a
    file of another time window (an EMG exported with an offset, a muscle analysis of other
    frames) would silently pair values of different instants. Row counts are checked elsewhere.
    """
    n = reference.n_rows
    if other.n_rows < padding + n or n == 0:
        return
    times = other.time[padding : padding + n]
    step = float(np.median(np.diff(reference.time))) if n > 1 else 0.0
    bad = np.flatnonzero(np.abs(times - reference.time) > 0.25 * step + 1e-9 * np.maximum(1.0, np.abs(reference.time)))
    if not bad.size:
        return
    k = int(bad[0])
    source = reference.source
    ref_name = f"{source.parent.name}/{source.name}" if source is not None else "the ID file"
    rows = f"row {padding + k + 1}" + (f" (ID row {k + 1}; {padding} padding rows before it)" if padding else "")
    other_step = float(np.median(np.diff(other.time))) if other.n_rows > 1 else step
    rate = ""
    if step > 0 and abs(other_step / step - 1000.0) <= 10.0:  # a unit, not a rate
        rate = f"; it is sampled every {other_step:.6g} s, {ref_name} every {step:.6g} s: are its times in milliseconds?"
    elif step > 0 and abs(other_step / step - 1.0) > 0.01:
        rate = (f"; it is sampled every {other_step:.6g} s, {ref_name} every {step:.6g} s (resample it to the ID "
                "frames, as preprocessing does)")
    raise InputError(
        f"trial '{prefix}': data {rows} is at {float(times[k])!r} s but {ref_name} is at "
        f"{float(reference.time[k])!r} s (off by {float(times[k] - reference.time[k]):.6g} s){rate}",
        file=other.source,
        element="column 'time'",
        expected=f"the times of {ref_name}"
        + (f", with {padding} EMG rows before and after them" if padding else "")
        + ": its rows are paired with the ID file's by position, so they must be sampled at the same frames",
    )


#: processed EMG below this is reported (real envelopes reach -7e-7 from filter round-off)
EMG_NEGATIVE_REPORTED = -0.01
#: an EMG sample interval above this (s) is reported as probably milliseconds
EMG_LONGEST_STEP = 0.5


def check_emg(table: Table, channels: Sequence[str]) -> None:
    """Warnings for processed EMG a run would use without complaint but that is likely wrong:
    a channel with the same value in every row (a dead or unplugged electrode: its muscles get
    no excitation whatever their scale factor), values below -0.01 (an envelope is >= 0; the
    excitations and the results would carry them). A sample interval above 0.5 s (times in
    milliseconds: the activation dynamics would see 1000 times the real interval) is an
    :class:`InputError`."""
    where = table.source if table.source is not None else "EMG"
    dead = [c for c in channels if np.ptp(table.column(c)) <= 1e-12 * max(1.0, float(np.abs(table.column(c)).max()))]
    if dead:
        warnings.warn(
            f"{where}: EMG channel(s) {', '.join(dead)} have the same value in every row (a dead channel?): "
            "their muscles get no excitation from them; list their groups in "
            "<missing_emg_channel_muscle_groups> instead of <collected_emg_channel_muscle_groups> to have them "
            "estimated, or fix the EMG",
            stacklevel=3,
        )
    for c in channels:
        values = table.column(c)
        k = int(np.argmin(values))
        if values[k] < EMG_NEGATIVE_REPORTED:
            n_bad = int(np.count_nonzero(values < EMG_NEGATIVE_REPORTED))
            warnings.warn(
                f"{where}: column '{c}': processed EMG reaches {float(values[k]):.4g} at {float(table.time[k]):.6g} s "
                f"({n_bad} row(s) below {EMG_NEGATIVE_REPORTED}); a rectified, normalized envelope is >= 0 and "
                "negative values give negative excitations",
                stacklevel=3,
            )
    if table.n_rows > 1:
        step = float(np.median(np.diff(table.time)))
        if step > EMG_LONGEST_STEP:
            raise InputError(
                f"the EMG sample interval is {step:.6g} s: are the times in milliseconds?",
                file=table.source,
                element="column 'time'",
                expected=f"times in seconds, sampled at most {EMG_LONGEST_STEP} s apart (the activation dynamics "
                "have time constants of about 0.015 s)",
            )


def read_moment_arms(
    folder: Path, prefix: str, coordinates: Sequence[str], muscles: Sequence[str], *, reference: Table | None = None
) -> np.ndarray:
    """Moment arms (n_frames, n_coordinates, n_muscles) from ``<prefix>_MomentArm_<coord>.sto`` files;
    ``reference``: the trial's ID table, whose times each file's rows must have."""
    arms = []
    for coordinate in coordinates:
        try:
            path = find_file_by_suffix(folder, f"_MomentArm_{coordinate}")
        except InputError as exc:
            raise InputError(
                f"moment-arm file missing for coordinate '{coordinate}' of trial '{prefix}'",
                file=folder,
                element=f"{prefix}_MomentArm_{coordinate}.sto",
                expected="a MuscleAnalysis moment-arm table for every coordinate in <coordinate_list>",
            ) from exc
        table = read_storage(path)
        arms.append(_columns(table, muscles, f"moment-arm file for '{coordinate}'"))
        if reference is not None and table.n_rows == reference.n_rows:
            check_same_times(reference, table, prefix)
    return np.stack(arms, axis=1)


def emg_padding(n_emg: int, n_frames: int, source: Path | None = None) -> int:
    """Padding frames per side: ``(n_emg - n_frames) / 2``; error unless a non-negative integer."""
    extra = n_emg - n_frames
    if extra < 0 or extra % 2:
        raise InputError(
            f"EMG has {n_emg} rows but ID/MA have {n_frames}: the difference must be even and >= 0",
            file=source,
            expected=f"{n_frames} + 2 * padding rows (EMG padded equally on both sides)",
        )
    return extra // 2


def load_trial(
    data_directory: str | os.PathLike[str],
    prefix: str,
    coordinates: Sequence[str],
    muscles: Sequence[str],
    emg_channels: Sequence[str] | None = None,
    *,
    ma_directory: str | os.PathLike[str] | None = None,
) -> TrialData:
    """Read one trial: ID, MA (lengths, velocities, moment arms) and, if asked, EMG channels."""
    root = Path(data_directory)
    id_path = find_trial_file(root / "IDData", prefix)
    id_table = read_storage(id_path)
    moments = np.column_stack([id_table.load_column(c) for c in coordinates]) if coordinates else np.zeros((id_table.n_rows, 0))
    ma_root = Path(ma_directory) if ma_directory is not None else root / "MAData"
    with _trial_origin(prefix, root):
        folder = find_trial_folder(ma_root, prefix)
    length = read_storage(find_file_by_suffix(folder, "_Length"))
    velocity = read_storage(find_file_by_suffix(folder, "_Velocity"))
    lmt = _columns(length, muscles, "muscle-tendon length file")
    vmt = _columns(velocity, muscles, "muscle-tendon velocity file")
    arms = read_moment_arms(folder, prefix, coordinates, muscles, reference=id_table)
    n = id_table.n_rows
    for name, arr, src in (("length", lmt, length.source), ("velocity", vmt, velocity.source)):
        if arr.shape[0] != n:
            raise InputError(
                f"trial '{prefix}': muscle-tendon {name} has {arr.shape[0]} rows but ID has {n}",
                file=src,
                expected="MAData and IDData sampled at the same frames",
            )
    if arms.shape[0] != n:
        raise InputError(f"trial '{prefix}': moment arms have {arms.shape[0]} rows but ID has {n}", file=folder)
    check_same_times(id_table, length, prefix)
    check_same_times(id_table, velocity, prefix)
    emg_time = emg = None
    padding = 0
    if emg_channels is not None:
        with _trial_origin(prefix, root):
            emg_path = find_trial_file(root / "EMGData", prefix)
        emg_table = read_storage(emg_path)
        emg = _columns(emg_table, emg_channels, "EMG file")
        emg_time = emg_table.time
        padding = emg_padding(emg_table.n_rows, n, emg_path)
        check_same_times(id_table, emg_table, prefix, padding=padding)
        check_emg(emg_table, emg_channels)
    return TrialData(
        name=prefix,
        time=id_table.time,
        muscle_tendon_length=lmt,
        muscle_tendon_velocity=vmt,
        moment_arms=arms,
        inverse_dynamics_moments=moments,
        emg_time=emg_time,
        emg=emg,
        padding=padding,
    )


@contextlib.contextmanager
def _trial_origin(prefix: str, root: Path) -> Iterator[None]:
    """Say where a trial name came from when another folder has nothing for it (a renamed
    IDData file shows up as a trial the other folders lack)."""
    try:
        yield
    except InputError as exc:
        note = (f"; trial '{prefix}' is a file name of {root / 'IDData'} (the trials are those files unless "
                "<trial_prefixes> lists them)")
        raise InputError(exc.detail + note, file=exc.file, line=exc.line, element=exc.element,
                         expected=exc.expected) from exc


def find_prefixes(data_directory: str | os.PathLike[str], requested: Sequence[str] = ()) -> list[str]:
    """Trial prefixes: the requested ones, else the IDData file names (else IKData)."""
    if requested:
        return list(requested)
    root = Path(data_directory)
    for sub in ("IDData", "IKData"):
        if (root / sub).is_dir():
            found = trial_prefixes(root / sub)
            if found:
                return found
    raise InputError(
        "no trials found", file=root, expected="IDData/<trial>.sto files or a <trial_prefixes> list"
    )


def check_same_frame_counts(trials: Sequence[TrialData]) -> None:
    """MTP stacks trials: all need the same number of ID/MA frames and EMG frames."""
    if not trials:
        return
    n = {t.name: t.n_frames for t in trials}
    if len(set(n.values())) > 1:
        raise InputError(
            "trials have different frame counts: " + ", ".join(f"{k}: {v}" for k, v in n.items()),
            element="IDData/MAData",
            expected="the same number of rows in every trial (Preprocessing resamples to 101)",
        )
    ne = {t.name: (None if t.emg is None else t.emg.shape[0]) for t in trials}
    if len(set(ne.values())) > 1:
        raise InputError(
            "trials have different EMG frame counts: " + ", ".join(f"{k}: {v}" for k, v in ne.items()),
            element="EMGData",
            expected="the same number of EMG rows (and padding) in every trial",
        )

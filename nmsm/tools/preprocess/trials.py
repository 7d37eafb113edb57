"""Split long recordings into trials in the personalization layout (``splitIntoTrials``).

For each time pair ``(t0, t1)`` (s), trial ``<prefix>_<k>`` (k from 1, or the given names):

* ``IKData``, ``IDData``, ``GRFData``: ``rows`` evenly spaced samples on ``[t0, t1]``
  (101 by default), natural quintic (GCV) spline; IK in radians for rotational
  coordinates (converted when the file says degrees; needs the model's rotational
  coordinates) unless ``ik_radians=False`` keeps the input's unit; IK and ID low-passed
  first at ``cutoff`` Hz (GRF not). Ground-reaction columns with NaN gaps (centre of
  pressure in swing) are interpolated linearly keeping the gaps
  (:func:`~nmsm.tools.preprocess.signals.resample_with_gaps`);
* ``MAData/<name>/<name>_Length.sto``, ``_Velocity.sto`` and ``_MomentArm_<coordinate>.sto``:
  likewise (lengths and moment arms low-passed, velocities not);
* ``EMGData``: the pair widened by ``pad / (rows - 1) (t1 - t0)`` each side, ``rows + 2 pad``
  samples, ``pad = ceil(emg_padding_time / (shortest trial / (rows - 1)))`` frames (0.2 s by
  default: room for the electromechanical delay and activation dynamics); processed EMG is
  not filtered again. ``clip_emg`` sets the spline's small undershoots below 0 to 0 (the
  original keeps them).

Sources are paths or tables (:class:`~nmsm.io.storage.Table`); outputs are written with
:func:`nmsm.io.storage.write_storage`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Collection, Mapping, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.storage import Table, write_storage
from nmsm.io.motion_units import warn_implausible_angles
from nmsm.tools.preprocess.signals import lowpass, resample, resample_with_gaps
from nmsm.tools.preprocess.tables import read_table

#: seconds of EMG kept before and after each trial
EMG_PADDING_SECONDS = 0.2

SourceLike = Path | Table | None


@attrs.frozen
class TrialSources:
    """Inputs of :func:`split_into_trials` (paths or tables); any may be None (then not written).

    ``rotational``: the model's rotational coordinate names (for IK in degrees), or a mapping
    name -> range ``(min, max)`` (rad) of them; given, the IK file's ``inDegrees`` header is
    checked for plausibility (:mod:`nmsm.io.motion_units`).
    ``muscle_analysis``: folder with ``*_Length.sto``, ``*_Velocity.sto``,
    ``*_MomentArm_<coordinate>.sto`` (OpenSim MuscleAnalysis names).
    """

    ik: SourceLike = None
    inverse_dynamics: SourceLike = None
    grf: SourceLike = None
    emg: SourceLike = None
    muscle_analysis: Path | None = None
    rotational: Collection[str] | Mapping[str, tuple[float, float]] = ()


def ground_reaction_nan(label: str) -> bool:
    """NaN is allowed in centre-of-pressure columns of ground-reaction files (swing)."""
    return label.endswith(("_px", "_py", "_pz"))


def padding_frames(time_pairs: Sequence[tuple[float, float]], rows: int = 101,
                   padding_time: float = EMG_PADDING_SECONDS) -> int:
    """EMG padding frames of the shortest trial: ``ceil(padding_time / (T_min / (rows - 1)))``."""
    shortest = min(t1 - t0 for t0, t1 in time_pairs)
    return int(math.ceil(round(padding_time / (shortest / (rows - 1)), 9)))


def check_time_pairs(time_pairs: Sequence[tuple[float, float]], element: str = "time pairs") -> None:
    """:class:`InputError` for no pair, a non-finite time or a pair that does not increase."""
    if not time_pairs:
        raise InputError("no time pairs", element=element, expected="at least one 'start end' pair (s)")
    for t0, t1 in time_pairs:
        if not (math.isfinite(t0) and math.isfinite(t1)):
            raise InputError(f"time pair {t0} {t1} is not finite", element=element, expected="finite times (s)")
        if not t1 > t0:
            raise InputError(f"time pair {t0} {t1} does not increase", element=element, expected="start < end (s)")


def emg_windows(time_pairs: Sequence[tuple[float, float]], rows: int = 101,
                padding_time: float = EMG_PADDING_SECONDS, *, per_window: bool = False) -> list[tuple[float, float]]:
    """The EMG windows (s): each pair widened by ``pad / (rows - 1) (t1 - t0)`` each side
    (``pad``: :func:`padding_frames` of all pairs, or of each pair alone with ``per_window``)."""
    pads = _padding_per_pair(time_pairs, rows, padding_time, per_window)
    return [(t0 - pad / (rows - 1) * (t1 - t0), t1 + pad / (rows - 1) * (t1 - t0))
            for pad, (t0, t1) in zip(pads, time_pairs)]


def _padding_per_pair(time_pairs: Sequence[tuple[float, float]], rows: int, padding_time: float,
                      per_window: bool) -> list[int]:
    if per_window:
        return [padding_frames([pair], rows, padding_time) for pair in time_pairs]
    return [padding_frames(time_pairs, rows, padding_time)] * len(time_pairs)


def _write(path: Path, like: Table, time: np.ndarray, values: np.ndarray, *, in_degrees: bool = False,
           allow_nan: bool = False) -> Path:
    finite = np.isfinite(values) | (np.isnan(values) if allow_nan else False)
    if not np.all(finite):
        raise InputError(f"non-finite values while writing {path.name}", file=like.source or path,
                         expected="finite input data")
    path.parent.mkdir(parents=True, exist_ok=True)
    table = Table(time=time, labels=like.labels, data=values, in_degrees=in_degrees, name=path.stem)
    return write_storage(path, table)


def _filtered(table: Table, cutoff: float | None, order: int) -> Table:
    if cutoff is None:
        return table
    return attrs.evolve(table, data=lowpass(table.time, table.data, cutoff, order))


def _section(table: Table, pairs: Sequence[tuple[float, float]], rows: int, what: str) -> list[tuple[np.ndarray, np.ndarray]]:
    out = []
    for t0, t1 in pairs:
        times = np.linspace(t0, t1, rows)
        out.append((times, resample(table, times, what=what)))
    return out


def _section_with_gaps(table: Table, pairs: Sequence[tuple[float, float]], rows: int,
                       what: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """Spline columns without NaN, gap-keeping linear interpolation of columns with NaN."""
    gaps = np.isnan(table.data).any(axis=0)
    if not gaps.any():
        return _section(table, pairs, rows, what)
    full = attrs.evolve(table, data=np.where(gaps, 0.0, table.data))
    out = []
    for times, values in _section(full, pairs, rows, what):
        values[:, gaps] = resample_with_gaps(table.time, table.data[:, gaps], times)
        out.append((times, values))
    return out


def ma_files(folder: Path) -> dict[str, Path]:
    """``"Length"``, ``"Velocity"``, ``"MomentArm_<coordinate>"`` -> file in an MA folder."""
    if not folder.is_dir():
        raise InputError("muscle-analysis folder not found", file=folder, expected="a folder of MuscleAnalysis files")
    found: dict[str, Path] = {}
    for path in sorted(folder.iterdir()):
        if path.suffix.lower() not in (".sto", ".mot"):
            continue
        stem = path.stem
        if stem.endswith("_Length"):
            found["Length"] = path
        elif stem.endswith("_Velocity"):
            found["Velocity"] = path
        elif "_MomentArm_" in stem:
            found["MomentArm_" + stem.split("_MomentArm_", 1)[1]] = path
    if "Length" not in found:
        raise InputError("no muscle-tendon length file", file=folder, expected="a '*_Length.sto' MuscleAnalysis file")
    return found


def split_into_trials(
    time_pairs: Sequence[tuple[float, float]],
    sources: TrialSources,
    results_directory: str | os.PathLike[str],
    *,
    prefix: str = "trial",
    names: Sequence[str] | None = None,
    rows: int = 101,
    cutoff: float | None = 6.0,
    filter_order: int = 4,
    emg_padding_time: float = EMG_PADDING_SECONDS,
    emg_padding_per_window: bool = False,
    ik_radians: bool = True,
    clip_emg: bool = False,
) -> list[str]:
    """Write the trials; returns their names (``names`` or ``<prefix>_<k>``). The EMG padding
    is that of the shortest pair, or each pair's own with ``emg_padding_per_window`` (the
    pipeline's ``<DataPreprocessingTool>`` stage)."""
    check_time_pairs(time_pairs)
    out = Path(results_directory)
    names = list(names) if names is not None else [f"{prefix}_{k}" for k in range(1, len(time_pairs) + 1)]
    if len(names) != len(time_pairs):
        raise InputError(f"{len(names)} trial names for {len(time_pairs)} time pairs", element="names",
                         expected="one name per time pair")
    if sources.ik is not None:
        table = read_table(sources.ik)
        if sources.rotational:
            warn_implausible_angles(table, sources.rotational)
        degrees = table.in_degrees
        if degrees and ik_radians:
            if not sources.rotational:
                raise InputError("IK file is in degrees but no model was given to tell rotational coordinates",
                                 file=table.source, expected="the model (.osim) of the motion")
            table, degrees = table.to_radians(sources.rotational), False
        for name, (t, v) in zip(names, _section(_filtered(table, cutoff, filter_order), time_pairs, rows, "IK")):
            _write(out / "IKData" / f"{name}.sto", table, t, v, in_degrees=degrees)
    if sources.inverse_dynamics is not None:
        table = read_table(sources.inverse_dynamics)
        for name, (t, v) in zip(names, _section(_filtered(table, cutoff, filter_order), time_pairs, rows, "ID")):
            _write(out / "IDData" / f"{name}.sto", table, t, v)
    if sources.grf is not None:
        table = read_table(sources.grf, allow_nan=ground_reaction_nan)
        for name, (t, v) in zip(names, _section_with_gaps(table, time_pairs, rows, "GRF")):
            _write(out / "GRFData" / f"{name}.sto", table, t, v, allow_nan=True)
    if sources.muscle_analysis is not None:
        files = ma_files(Path(sources.muscle_analysis))
        if "Velocity" not in files:
            raise InputError("no muscle-tendon velocity file", file=sources.muscle_analysis,
                             expected="a '*_Velocity.sto' (make one with nmsm.tools.preprocess.velocity)")
        for key, path in files.items():
            table = read_table(path)
            filtered = _filtered(table, cutoff if key != "Velocity" else None, filter_order)
            for name, (t, v) in zip(names, _section(filtered, time_pairs, rows, f"MuscleAnalysis {key}")):
                _write(out / "MAData" / name / f"{name}_{key}.sto", table, t, v)
    if sources.emg is not None:
        table = read_table(sources.emg)
        pads = _padding_per_pair(time_pairs, rows, emg_padding_time, emg_padding_per_window)
        windows = emg_windows(time_pairs, rows, emg_padding_time, per_window=emg_padding_per_window)
        for name, pad, (start, end) in zip(names, pads, windows):
            times = np.linspace(start, end, rows + 2 * pad)
            values = resample(table, times, what="EMG")
            _write(out / "EMGData" / f"{name}.sto", table, times, np.clip(values, 0.0, None) if clip_emg else values)
    return names


__all__ = ["EMG_PADDING_SECONDS", "TrialSources", "check_time_pairs", "emg_windows", "ground_reaction_nan",
           "ma_files", "padding_frames", "split_into_trials"]

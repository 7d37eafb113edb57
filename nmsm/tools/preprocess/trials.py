"""Split long recordings into trials in the personalization layout (``splitIntoTrials``).

For each time pair ``(t0, t1)`` (s), trial ``<prefix>_<k>`` (k from 1):

* ``IKData``, ``IDData``, ``GRFData``: ``rows`` evenly spaced samples on ``[t0, t1]``
  (101 by default), natural quintic (GCV) spline; IK in radians for rotational
  coordinates (converted when the file says degrees; needs the model), IK and ID low-passed
  first at ``cutoff`` Hz (GRF not);
* ``MAData/<prefix>_<k>/<prefix>_<k>_Length.sto``, ``_Velocity.sto`` and
  ``_MomentArm_<coordinate>.sto``: likewise (lengths and moment arms low-passed, velocities
  not);
* ``EMGData``: the pair widened by ``pad / (rows - 1) (t1 - t0)`` each side, ``rows + 2 pad``
  samples, ``pad = ceil(0.2 s / (shortest trial / (rows - 1)))`` frames (enough for the
  electromechanical delay and activation dynamics); processed EMG is not filtered again.

Output tables are written with :func:`nmsm.io.storage.write_storage`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Collection, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage, table_from_columns, write_storage
from nmsm.tools.preprocess.signals import lowpass, resample

#: seconds of EMG kept before and after each trial
EMG_PADDING_SECONDS = 0.2


@attrs.frozen
class TrialSources:
    """Inputs of :func:`split_into_trials`; any may be None (then not written).

    ``rotational``: the model's rotational coordinate names (for IK in degrees).
    ``muscle_analysis``: folder with ``*_Length.sto``, ``*_Velocity.sto``,
    ``*_MomentArm_<coordinate>.sto`` (OpenSim MuscleAnalysis names).
    """

    ik: Path | None = None
    inverse_dynamics: Path | None = None
    grf: Path | None = None
    emg: Path | None = None
    muscle_analysis: Path | None = None
    rotational: Collection[str] = ()


def padding_frames(time_pairs: Sequence[tuple[float, float]], rows: int = 101) -> int:
    """EMG padding frames of the shortest trial: ``ceil(0.2 / (T_min / (rows - 1)))``."""
    shortest = min(t1 - t0 for t0, t1 in time_pairs)
    return int(math.ceil(round(EMG_PADDING_SECONDS / (shortest / (rows - 1)), 9)))


def check_time_pairs(time_pairs: Sequence[tuple[float, float]]) -> None:
    if not time_pairs:
        raise InputError("no time pairs", element="time pairs", expected="at least one 'start end' pair (s)")
    for t0, t1 in time_pairs:
        if not t1 > t0:
            raise InputError(f"time pair {t0} {t1} does not increase", element="time pairs", expected="start < end (s)")


def _write(path: Path, time: np.ndarray, labels: Sequence[str], values: np.ndarray) -> Path:
    if not np.all(np.isfinite(values)):
        raise InputError(f"non-finite values while writing {path.name}", file=path, expected="finite input data")
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_storage(path, table_from_columns(time, {label: values[:, i] for i, label in enumerate(labels)}, name=path.stem))


def _section(table: Table, pairs: Sequence[tuple[float, float]], rows: int, cutoff: float | None,
             what: str) -> list[tuple[np.ndarray, np.ndarray]]:
    data = table
    if cutoff is not None:
        data = attrs.evolve(table, data=lowpass(table.time, table.data, cutoff))
    out = []
    for t0, t1 in pairs:
        times = np.linspace(t0, t1, rows)
        out.append((times, resample(data, times, what=what)))
    return out


def _ma_files(folder: Path) -> dict[str, Path]:
    """``"Length"``, ``"Velocity"``, ``"MomentArm_<coordinate>"`` -> file in an MA folder."""
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
    rows: int = 101,
    cutoff: float | None = 6.0,
) -> list[str]:
    """Write the trials; returns their names (``<prefix>_<k>``)."""
    check_time_pairs(time_pairs)
    out = Path(results_directory)
    names = [f"{prefix}_{k}" for k in range(1, len(time_pairs) + 1)]
    if sources.ik is not None:
        table = read_storage(sources.ik)
        if table.in_degrees:
            if not sources.rotational:
                raise InputError("IK file is in degrees but no model was given to tell rotational coordinates",
                                 file=sources.ik, expected="the model (.osim) of the motion")
            table = table.to_radians(sources.rotational)
        for name, (t, v) in zip(names, _section(table, time_pairs, rows, cutoff, "IK")):
            _write(out / "IKData" / f"{name}.sto", t, table.labels, v)
    for source, folder, filtered in ((sources.inverse_dynamics, "IDData", True), (sources.grf, "GRFData", False)):
        if source is None:
            continue
        table = read_storage(source, allow_nan=(lambda label: label.endswith(("_px", "_py", "_pz"))) if folder == "GRFData" else None)
        if folder == "GRFData" and np.isnan(table.data).any():
            table = attrs.evolve(table, data=np.nan_to_num(table.data, nan=0.0))
        for name, (t, v) in zip(names, _section(table, time_pairs, rows, cutoff if filtered else None, folder)):
            _write(out / folder / f"{name}.sto", t, table.labels, v)
    if sources.muscle_analysis is not None:
        files = _ma_files(Path(sources.muscle_analysis))
        if "Velocity" not in files:
            raise InputError("no muscle-tendon velocity file", file=sources.muscle_analysis,
                             expected="a '*_Velocity.sto' (make one with nmsm.tools.preprocess.velocity)")
        for key, path in files.items():
            table = read_storage(path)
            filtered = cutoff if key != "Velocity" else None
            for name, (t, v) in zip(names, _section(table, time_pairs, rows, filtered, f"MuscleAnalysis {key}")):
                _write(out / "MAData" / name / f"{name}_{key}.sto", t, table.labels, v)
    if sources.emg is not None:
        table = read_storage(sources.emg)
        pad = padding_frames(time_pairs, rows)
        for name, (t0, t1) in zip(names, time_pairs):
            widen = pad / (rows - 1) * (t1 - t0)
            times = np.linspace(t0 - widen, t1 + widen, rows + 2 * pad)
            _write(out / "EMGData" / f"{name}.sto", times, table.labels, resample(table, times, what="EMG"))
    return names

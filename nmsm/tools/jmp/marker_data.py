"""Experimental markers prepared for inverse kinematics and JMP.

:func:`select_trial` picks the markers (names and weights) and the frames (time range) of a
:class:`~nmsm.io.trc.MarkerTable`, checking every name against the file and the model.
:func:`check_units` compares the size of the experimental marker cloud with the model's and
rescales a file whose ``Units`` header disagrees with its numbers (mm written as m, or m
as mm), with a warning.

Gaps (NaN) stay NaN in ``positions``; :meth:`MarkerTrial.sqrt_weights` gives weight 0 to a
gap, so that marker is dropped from that frame, as OpenSim does.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.io.trc import MarkerTable
from nmsm.model.components import Model


@attrs.frozen(eq=False)
class MarkerTrial:
    """Markers of one trial: ``time (F,)`` s, ``names (M,)``, ``positions (F, M, 3)`` m (NaN
    gaps), ``weights (M,)`` (relative, > 0), ``source`` the marker file."""

    time: np.ndarray
    names: tuple[str, ...]
    positions: np.ndarray
    weights: np.ndarray
    source: str | None = None

    @property
    def n_frames(self) -> int:
        return int(self.time.size)

    @property
    def n_markers(self) -> int:
        return len(self.names)

    @property
    def present(self) -> np.ndarray:
        """``(F, M)`` True where the marker has data."""
        return np.all(np.isfinite(self.positions), axis=2)

    def sqrt_weights(self) -> np.ndarray:
        """``(F, M)`` square roots of the weights, 0 in gaps."""
        return np.where(self.present, np.sqrt(self.weights)[None, :], 0.0)

    def filled_positions(self) -> np.ndarray:
        """``positions`` with gaps replaced by 0 (harmless: their weight is 0)."""
        return np.where(np.isfinite(self.positions), self.positions, 0.0)

    def scaled(self, factor: float) -> MarkerTrial:
        return attrs.evolve(self, positions=self.positions * factor)


def _where(table: MarkerTable) -> str | None:
    return str(table.source) if table.source else None


def select_trial(table: MarkerTable, model: Model, weights: Mapping[str, float] | None = None, *,
                 time_range: tuple[float, float] | None = None, settings_file: str | None = None,
                 element: str = "<marker_names>", time_range_source: str | None = None,
                 skip_missing: bool = False) -> MarkerTrial:
    """The markers and frames used.

    ``weights`` (marker -> weight > 0) names the markers explicitly: each must be in the
    marker file and in the model, else :class:`InputError` naming ``settings_file`` and
    ``element``; with ``skip_missing`` (an OpenSim IK task set, which OpenSim's IK tool reads
    this way) such markers are left out with one warning naming them. Without ``weights``, every marker of both the file and the model is used
    with weight 1 (OpenSim's default). ``time_range`` (s, inclusive) selects frames; a
    finite end reaching more than half a frame beyond the marker data warns, naming
    ``time_range_source`` (default ``settings_file``), ``<time_range>``, the requested and
    the available range.
    """
    if weights is None:
        names = [n for n in table.names if n in set(model.marker_names)]
        if not names:
            raise InputError("no marker of the marker file is a marker of the model", file=_where(table),
                             expected=f"marker names shared with {model.file}")
        _warn_unmatched_markers(table, model, names)
        values = np.ones(len(names))
    else:
        names, values_list = [], []
        skipped: dict[str, list[str]] = {}
        for name, weight in weights.items():
            if not weight > 0:
                continue
            absent = False
            for where, pool, what in ((_where(table), table.names, "marker file"),
                                      (model.file, model.marker_names, "model")):
                if name in pool:
                    continue
                close = ", ".join(close_matches(name, list(pool)))
                if not skip_missing:
                    hint = f"; close matches: {close}" if close else ""
                    raise InputError(f"marker '{name}' is not in the {what} {where}{hint}", file=settings_file or where,
                                     element=element, expected="markers present in both the marker file and the model")
                shown = name + (f" (close: {close})" if close else "")
                skipped.setdefault(f"not in the {what} {where}", []).append(shown)
                absent = True
                break
            if absent:
                continue
            names.append(name)
            values_list.append(float(weight))
        if skipped:
            where = f"{settings_file}: " if settings_file else ""
            reasons = "; ".join(f"{why}: {_few(found)}" for why, found in skipped.items())
            warnings.warn(f"{where}{element} task(s) skipped, as OpenSim's IK tool skips them: {reasons}", stacklevel=2)
        if not names:
            raise InputError("no marker has a positive weight", file=settings_file, element=element,
                             expected="at least one marker with weight > 0")
        values = np.array(values_list)
    index = [table.index(n) for n in names]
    time = table.time
    positions = table.positions[:, index, :]
    if time_range is not None:
        start, end = time_range
        keep = frames_in_range(time, start, end)
        if not keep.any():
            raise InputError(f"no frame of the marker file lies in the time range {start:g}-{end:g} s "
                             f"(the file covers {time[0]:g}-{time[-1]:g} s)", file=settings_file or _where(table),
                             element="<time_range>", expected="a time range overlapping the marker data")
        _warn_range_beyond_data(time, start, end, keep, time_range_source or settings_file, table)
        time, positions = time[keep], positions[keep]
    present = np.all(np.isfinite(positions), axis=2)
    never = [n for k, n in enumerate(names) if not present[:, k].any()]
    if never:
        warnings.warn(f"{_where(table)}: marker(s) {', '.join(never)} have no data in the frames used; ignored "
                      "(weight 0 in every frame)", stacklevel=2)
    empty = np.flatnonzero(~(present & (values > 0)).any(axis=1)) if present.size else np.zeros(0, dtype=int)
    if empty.size and len(never) < len(names):
        shown = ", ".join(f"{time[i]:g}" for i in empty[:NAMED_MARKERS])
        more = f" and {empty.size - NAMED_MARKERS} more" if empty.size > NAMED_MARKERS else ""
        warnings.warn(f"{_where(table)}: {empty.size} frame(s) have no marker data (t = {shown}{more} s): nothing "
                      "determines their pose, so their coordinates repeat the previous frame's (or follow the "
                      "coordinate tasks); leave them out with a time range, or fill the gaps", stacklevel=2)
    return MarkerTrial(time=np.array(time), names=tuple(names), positions=np.array(positions),
                       weights=values, source=_where(table))


#: names listed in a warning before "and N more"
NAMED_MARKERS = 5


def _few(names: list[str]) -> str:
    """The first :data:`NAMED_MARKERS` names, then 'and N more'."""
    text = ", ".join(names[:NAMED_MARKERS])
    return text + (f" and {len(names) - NAMED_MARKERS} more" if len(names) > NAMED_MARKERS else "")


def _warn_unmatched_markers(table: MarkerTable, model: Model, used: list[str]) -> None:
    """Warn when model markers are missing from the marker file (they are left out of the
    fit), naming them and the file's markers that are not model markers."""
    in_file = set(table.names)
    missing = [n for n in model.marker_names if n not in in_file]
    if not missing:
        return
    in_model = set(model.marker_names)
    unknown = [n for n in table.names if n not in in_model]
    text = (f"{_where(table)}: model marker(s) {_few(missing)} of {model.file} are not in the marker file; "
            f"they are left out (the fit uses the other {len(used)})")
    if unknown:
        text += f"; the file's marker(s) {_few(unknown)} are not markers of the model"
        hints = [f"{m} ~ {close[0]}" for m in missing if (close := close_matches(m, unknown, n=1))]
        if hints:
            text += f" (renamed? {', '.join(hints[:NAMED_MARKERS])})"
    warnings.warn(text, stacklevel=3)


def frames_in_range(time: np.ndarray, start: float, end: float) -> np.ndarray:
    """``(F,)`` True for frames with ``start <= time <= end`` (s), to a round-off tolerance
    (1e-9 of the larger finite bound, at least 1e-9 s); an infinite bound is open-ended and a
    NaN bound selects nothing."""
    finite = [abs(b) for b in (start, end) if math.isfinite(b)]
    tol = 1e-9 * max([1.0, *finite])
    return (time >= start - tol) & (time <= end + tol)


def _warn_range_beyond_data(time: np.ndarray, start: float, end: float, keep: np.ndarray, source: str | None,
                            table: MarkerTable) -> None:
    half_frame = 0.5 * float(np.median(np.diff(time))) if time.size > 1 else 0.0
    beyond = ((math.isfinite(start) and start < time[0] - half_frame)
              or (math.isfinite(end) and end > time[-1] + half_frame))
    if not beyond:
        return
    used = time[keep]
    where = f"{source}: " if source else ""
    warnings.warn(f"{where}<time_range> {start:g}-{end:g} s reaches beyond the marker data {_where(table)} "
                  f"({time[0]:g}-{time[-1]:g} s); using its frames in {used[0]:g}-{used[-1]:g} s", stacklevel=4)


def _spread(points: np.ndarray) -> float:
    """RMS distance (m) of points ``(k, 3)`` from their centroid."""
    centred = points - points.mean(axis=0)
    return float(np.sqrt(np.mean(np.sum(centred**2, axis=1))))


def check_units(trial: MarkerTrial, model_positions: np.ndarray) -> tuple[MarkerTrial, float]:
    """Detect a marker file whose numbers are in mm but labelled m (or the reverse).

    ``model_positions`` ``(M, 3)`` are the model's markers (same order) in its default pose.
    The experimental marker cloud of the first frames is compared with the model's: sizes
    differing by a factor near 1000 mean a units mismatch; the trial is rescaled by 1e-3 (or
    1e3) with a warning. Returns ``(trial, factor applied)``.
    """
    present = trial.present
    if trial.n_markers < 2:
        return trial, 1.0
    ratios = []
    for k in range(min(trial.n_frames, 10)):
        use = present[k]
        if use.sum() < 2:
            continue
        model_size = _spread(model_positions[use])
        if model_size > 0:
            ratios.append(_spread(trial.positions[k, use]) / model_size)
    if not ratios:
        return trial, 1.0
    ratio = float(np.median(ratios))
    exponent = -np.log10(ratio)
    if abs(exponent) <= 0.5:
        return trial, 1.0
    k = int(np.round(exponent))
    if k in _UNIT_NAMES and abs(exponent - k) <= 0.5:
        factor = 10.0**k
        data_unit, labelled = _UNIT_NAMES[k]
        warnings.warn(
            f"{trial.source}: the marker positions are {ratio:.3g} times the size of the model's marker set: the "
            f"numbers look like {data_unit} while the file says {labelled}; rescaled by {factor:g} (fix the Units "
            "header to silence this)", stacklevel=2)
        return trial.scaled(factor), factor
    raise InputError(f"the marker positions are {ratio:.3g} times the size of the model's marker set, which no "
                     "unit conversion explains", file=trial.source, element="Units",
                     expected="marker data of the modelled subject in m, cm or mm")


#: power of ten applied -> (unit the numbers are in, unit the header claims), e.g. -3: mm read as m
_UNIT_NAMES = {-3: ("mm", "m"), -2: ("cm", "m"), -1: ("mm", "cm"), 1: ("cm", "mm"), 2: ("m", "cm"), 3: ("m", "mm")}

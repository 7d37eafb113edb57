"""Marker files (``.trc``).

Layout (tab separated)::

    PathFileType  4  (X/Y/Z)  <file name>
    DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
    <values of those keys>
    Frame#  Time  M1  <empty>  <empty>  M2 ...
    <empty>  <empty>  X1  Y1  Z1  X2 ...
    [blank line]
    1  0.00  x y z  x y z ...

Empty cells of the header-key and header-value lines are dropped, as OpenSim drops them (its
example files separate the values by two tabs). Marker names are taken in order; names not
three columns apart (one tab between them) are read as OpenSim reads them when their count
is ``NumMarkers``, and are an error otherwise (a name is then likely missing). Positions are converted to metres from
``Units`` (mm, cm, m). An empty or ``NaN`` entry is
a gap (NaN), as OpenSim treats it: that marker is dropped for that frame. Extra trailing
empty cells (written by spreadsheets) are ignored.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.io.numbers import full_precision
from nmsm.io.text import BOM, read_text_file

#: metres per unit
UNIT_SCALE: dict[str, float] = {"m": 1.0, "mm": 1e-3, "cm": 1e-2}
#: other spellings of ``Units`` that OpenSim's ``Units`` class reads (exactly these)
UNIT_ALIASES: dict[str, str] = {
    "M": "m", "METERS": "m", "meters": "m",
    "MM": "mm", "MILLIMETERS": "mm", "millimeters": "mm",
    "CM": "cm", "CENTIMETERS": "cm", "centimeters": "cm",
}
_HEADER_KEYS = (
    "DataRate",
    "CameraRate",
    "NumFrames",
    "NumMarkers",
    "Units",
    "OrigDataRate",
    "OrigDataStartFrame",
    "OrigNumFrames",
)


@attrs.frozen(eq=False)
class MarkerTable:
    """Marker trajectories.

    ``time`` (n,) s; ``positions`` (n, n_markers, 3) in metres, NaN for gaps;
    ``frames`` (n,) frame numbers. ``units`` and the rates are the file's metadata
    (``units`` is what :func:`write_trc` writes by default). Equality compares names,
    time, frames and positions (NaN equal to NaN).
    """

    time: np.ndarray
    names: tuple[str, ...]
    positions: np.ndarray
    frames: np.ndarray | None = None
    units: str = "m"
    data_rate: float | None = None
    camera_rate: float | None = None
    orig_data_rate: float | None = None
    orig_data_start_frame: int | None = None
    orig_num_frames: int | None = None
    file_label: str = ""
    source: Path | None = None

    def __attrs_post_init__(self) -> None:
        time = np.asarray(self.time, dtype=float).reshape(-1)
        pos = np.asarray(self.positions, dtype=float)
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "positions", pos)
        object.__setattr__(self, "names", tuple(self.names))
        frames = np.arange(1, time.size + 1) if self.frames is None else np.asarray(self.frames, dtype=int).reshape(-1)
        object.__setattr__(self, "frames", frames)
        if pos.shape != (time.size, len(self.names), 3):
            raise ValueError(f"positions have shape {pos.shape}, expected ({time.size}, {len(self.names)}, 3)")
        if frames.shape != time.shape:
            raise ValueError(f"frames have shape {frames.shape}, expected {time.shape}")
        if self.units not in UNIT_SCALE:
            raise ValueError(f"units must be one of {', '.join(UNIT_SCALE)}, got '{self.units}'")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, MarkerTable):
            return NotImplemented
        return (
            self.names == other.names
            and np.array_equal(self.time, other.time)
            and np.array_equal(self.frames, other.frames)
            and np.array_equal(self.positions, other.positions, equal_nan=True)
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def n_frames(self) -> int:
        return int(self.time.size)

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            close = close_matches(name, self.names)
            hint = f"; close matches: {', '.join(close)}" if close else ""
            raise InputError(
                f"marker '{name}' not in the marker file{hint}",
                file=self.source,
                line=4 if self.source else None,
                element=f"marker '{name}'",
                expected=f"one of the {len(self.names)} markers of the file",
            ) from None

    def marker(self, name: str) -> np.ndarray:
        """Trajectory of one marker, shape (n, 3), metres."""
        return self.positions[:, self.index(name), :]

    def select(self, names: Sequence[str]) -> MarkerTable:
        """A table with only ``names`` (in that order)."""
        idx = [self.index(n) for n in names]
        return attrs.evolve(self, names=tuple(names), positions=self.positions[:, idx, :])

    def between(self, start: float, end: float) -> MarkerTable:
        """Frames with ``start <= time <= end`` (s)."""
        keep = (self.time >= start) & (self.time <= end)
        return attrs.evolve(self, time=self.time[keep], positions=self.positions[keep], frames=self.frames[keep])


def _float_or_none(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _int_or_none(text: str) -> int | None:
    value = _float_or_none(text)
    return None if value is None or not float(value).is_integer() else int(value)


def read_trc(path: str | os.PathLike[str]) -> MarkerTable:
    """Read a ``.trc`` file; positions in metres (see module docstring)."""
    path = Path(path)
    try:
        text = read_text_file(path)
    except OSError as exc:
        raise InputError(
            f"cannot read marker file: {exc.strerror or exc}", file=path, expected="a readable .trc file"
        ) from exc
    return parse_trc(text, source=path)


def _cells(line: str) -> list[str]:
    cells = [c.strip() for c in line.rstrip("\r\n").split("\t")]
    while cells and cells[-1] == "":
        cells.pop()
    return cells


def _header_cells(line: str) -> list[str]:
    """The non-empty cells of a header line: OpenSim drops empty ones, so that values separated
    by two tabs (OpenSim's own example files) line up with their keys."""
    return [c for c in (c.strip() for c in line.rstrip("\r\n").split("\t")) if c]


def parse_trc(text: str, *, source: Path | None = None) -> MarkerTable:
    """Parse the text of a ``.trc`` file (see :func:`read_trc`)."""
    lines = text.removeprefix(BOM).splitlines()
    if len(lines) < 5 or not lines[0].startswith("PathFileType"):
        raise InputError(
            "not a marker file: the first line must start with 'PathFileType'",
            file=source,
            line=1,
            expected="a .trc file (PathFileType, header keys, header values, marker names, X/Y/Z labels, rows)",
        )
    first = _cells(lines[0])
    keys = _header_cells(lines[1])
    values = _header_cells(lines[2])
    if len(values) != len(keys):
        raise InputError(
            f"line 3 has {len(values)} values for the {len(keys)} keys of line 2",
            file=source,
            line=3,
            expected="one value per key (" + " ".join(keys) + ")",
        )
    header = dict(zip(keys, values))
    units = header.get("Units", "m").strip()
    units = UNIT_ALIASES.get(units, units)
    if units not in UNIT_SCALE:
        raise InputError(
            f"unknown units '{units}'",
            file=source,
            line=3,
            element="Units",
            expected="one of " + ", ".join([*UNIT_SCALE, *UNIT_ALIASES]) + " (as OpenSim reads them)",
        )
    name_cells = _cells(lines[3])
    if len(name_cells) < 2 or name_cells[0] != "Frame#":
        raise InputError(
            "marker-name line must start with 'Frame#' and 'Time'",
            file=source,
            line=4,
            expected="Frame#<tab>Time<tab>names",
        )
    names = [c for c in name_cells[2:] if c]
    positions_of_names = [j for j, c in enumerate(name_cells) if j >= 2 and c]
    declared = _int_or_none(header.get("NumMarkers", ""))
    for k, j in enumerate(positions_of_names):
        if j != 2 + 3 * k and declared != len(names):  # OpenSim takes the names in order when NumMarkers agrees
            raise InputError(
                f"marker '{name_cells[j]}' is in column {j + 1}; names must be 3 columns apart",
                file=source,
                line=4,
                element=f"column {j + 1}",
                expected=f"marker {k + 1} in column {3 + 3 * k}",
            )
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise InputError(
            f"duplicated marker name(s): {', '.join(duplicated)}", file=source, line=4, expected="unique marker names"
        )
    if declared is not None and declared != len(names):
        warnings.warn(
            f"{source}: NumMarkers={declared} but line 4 names {len(names)} markers; using the names", stacklevel=3
        )
    width = 2 + 3 * len(names)
    frames: list[float] = []
    times: list[float] = []
    rows: list[list[float]] = []
    row_lines: list[int] = []
    for i in range(5, len(lines)):
        line = lines[i]
        if not line.strip():
            continue
        cells = line.rstrip("\r\n").split("\t") if "\t" in line else line.split()
        if len(cells) > width:
            extra = [c for c in cells[width:] if c.strip()]
            if extra:
                raise InputError(
                    f"row has {len(cells)} values but there are {len(names)} markers ({width} columns)",
                    file=source,
                    line=i + 1,
                    element=f"column {width + 1}",
                    expected=f"{width} columns: Frame#, Time, then X Y Z per marker",
                )
            cells = cells[:width]
        if len(cells) < width:
            missing = len(cells)
            raise InputError(
                f"row has {len(cells)} values but there are {len(names)} markers ({width} columns)",
                file=source,
                line=i + 1,
                element=f"column {missing + 1}" + (f" (marker '{names[(missing - 2) // 3]}')" if missing >= 2 else ""),
                expected=f"{width} columns: Frame#, Time, then X Y Z per marker (empty cells for gaps)",
            )
        try:
            frames.append(float(cells[0]))
            times.append(float(cells[1]))
        except ValueError:
            raise InputError(
                "frame number and time must be numbers",
                file=source,
                line=i + 1,
                element="Frame#/Time",
                expected="numbers",
            ) from None
        row = []
        for j in range(2, width):
            cell = cells[j].strip()
            if cell == "":
                row.append(math.nan)
                continue
            try:
                value = float(cell)
                if math.isinf(value):  # 'inf' parses as a number; it would be taken for a gap, silently
                    raise ValueError(cell)
                row.append(value)
            except ValueError:
                raise InputError(
                    f"'{cell}' is not a number",
                    file=source,
                    line=i + 1,
                    element=f"column {j + 1} (marker '{names[(j - 2) // 3]}' {'XYZ'[(j - 2) % 3]})",
                    expected="a finite number, or an empty cell (or NaN) for a gap",
                ) from None
        rows.append(row)
        row_lines.append(i + 1)
    time = np.asarray(times, dtype=float)
    steps = np.diff(time)
    bad = np.flatnonzero(~(steps > 0))
    if bad.size:
        k = int(bad[0]) + 1
        raise InputError(
            f"time does not increase: {times[k - 1]!r} then {times[k]!r}",
            file=source,
            line=row_lines[k],
            element="column 2 (Time)",
            expected="strictly increasing time",
        )
    declared_frames = _int_or_none(header.get("NumFrames", ""))
    if declared_frames is not None and declared_frames != len(rows):
        warnings.warn(
            f"{source}: NumFrames={declared_frames} but the file has {len(rows)} rows; using the rows", stacklevel=3
        )
    positions = np.asarray(rows, dtype=float).reshape(len(rows), len(names), 3) * UNIT_SCALE[units]
    return MarkerTable(
        time=time,
        names=tuple(names),
        positions=positions,
        frames=np.asarray(frames, dtype=float).astype(int),
        units=units,
        data_rate=_float_or_none(header.get("DataRate", "")),
        camera_rate=_float_or_none(header.get("CameraRate", "")),
        orig_data_rate=_float_or_none(header.get("OrigDataRate", "")),
        orig_data_start_frame=_int_or_none(header.get("OrigDataStartFrame", "")),
        orig_num_frames=_int_or_none(header.get("OrigNumFrames", "")),
        file_label=first[3] if len(first) > 3 else "",
        source=source,
    )


def _rate(table: MarkerTable) -> float:
    if table.data_rate:
        return table.data_rate
    if table.n_frames > 1:
        return float((table.n_frames - 1) / (table.time[-1] - table.time[0]))
    return 0.0


def _num(value: float | int | None) -> str:
    if value is None:
        return ""
    return full_precision(float(value)) if not float(value).is_integer() else str(int(value))


def format_trc(table: MarkerTable, *, units: str | None = None, file_label: str | None = None) -> str:
    """The text of a ``.trc`` file; positions written in ``units`` (default: the table's)."""
    units = units or table.units
    if units not in UNIT_SCALE:
        raise ValueError(f"units must be one of {', '.join(UNIT_SCALE)}")
    rate = _rate(table)
    n = table.n_frames
    header_values: Mapping[str, str] = {
        "DataRate": _num(rate),
        "CameraRate": _num(table.camera_rate or rate),
        "NumFrames": str(n),
        "NumMarkers": str(len(table.names)),
        "Units": units,
        "OrigDataRate": _num(table.orig_data_rate or rate),
        "OrigDataStartFrame": str(table.orig_data_start_frame if table.orig_data_start_frame is not None else 1),
        "OrigNumFrames": str(table.orig_num_frames if table.orig_num_frames is not None else n),
    }
    out = ["\t".join(["PathFileType", "4", "(X/Y/Z)", file_label if file_label is not None else table.file_label])]
    out.append("\t".join(_HEADER_KEYS))
    out.append("\t".join(header_values[k] for k in _HEADER_KEYS))
    out.append("\t".join(["Frame#", "Time"] + [cell for name in table.names for cell in (name, "", "")]))
    out.append("\t".join(["", ""] + [f"{a}{k + 1}" for k in range(len(table.names)) for a in "XYZ"]))
    out.append("")
    scaled = table.positions / UNIT_SCALE[units]
    for i in range(n):
        cells = [str(int(table.frames[i])), full_precision(float(table.time[i]))]
        cells += ["" if math.isnan(v) else full_precision(v) for v in scaled[i].reshape(-1).tolist()]
        out.append("\t".join(cells))
    return "\n".join(out) + "\n"


def write_trc(path: str | os.PathLike[str], table: MarkerTable, *, units: str | None = None) -> Path:
    """Write ``table`` as a ``.trc`` file (gaps as empty cells)."""
    path = Path(path)
    path.write_text(format_trc(table, units=units, file_label=path.name), encoding="utf-8")
    return path

"""OpenSim ``.sto`` / ``.mot`` tables.

Both header styles are read: OpenSim 4 (``version=3``, ``DataType``, ``OpenSimVersion``) and
the older Storage style (a name line, ``version=1``, ``nRows``, ``nColumns``,
``inDegrees``, free description lines), each closed by ``endheader``; values are separated
by tabs or spaces. The first column is time (s).

Degrees: a table read from an ``inDegrees=yes`` file keeps the file's numbers and says so
(``in_degrees``). :meth:`Table.to_radians` converts only the columns named in the set of
the model's *rotational* coordinates it is given; it never guesses from a column name
(coupled coordinates such as ``knee_angle_r_beta`` stay as they are). Readers of ID, muscle
analysis and EMG data simply never call it.

NaN is an error unless the caller names the columns where it is allowed (``allow_nan``):
in GRF files the centre-of-pressure columns are NaN while the foot is in the air. An
infinite value (``inf``, ``Infinity``) is an error in every column.

Tables are written as OpenSim's ``Storage`` writes them: name line, ``version=1``,
``nRows``, ``nColumns``, ``inDegrees``, ``endheader``, tab-separated values in full double
precision.
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.io.numbers import full_precision
from nmsm.io.text import BOM, read_text_file

#: header keys the writer sets itself
_WRITER_KEYS = ("version", "nRows", "nColumns", "inDegrees")
#: suffixes of inverse-dynamics labels (``<coordinate>_moment`` / ``<coordinate>_force``)
LOAD_SUFFIXES = ("_moment", "_force")
#: suffixes of centre-of-pressure columns in OpenSim GRF files
COP_SUFFIXES = ("_px", "_py", "_pz")

NanPolicy = Collection[str] | Callable[[str], bool]


def strip_load_suffix(label: str) -> str:
    """``knee_angle_r_moment`` -> ``knee_angle_r``; labels without the suffix unchanged."""
    for suffix in LOAD_SUFFIXES:
        if label.endswith(suffix):
            return label[: -len(suffix)]
    return label


def center_of_pressure_columns(labels: Iterable[str]) -> list[str]:
    """Labels that look like OpenSim centre-of-pressure columns (``*_px``, ``*_py``, ``*_pz``)."""
    return [label for label in labels if label.endswith(COP_SUFFIXES)]


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=True))


@attrs.frozen(eq=False)
class Table:
    """A time table read from (or written to) ``.sto`` / ``.mot``.

    ``time`` (n,) in s; ``data`` (n, k) with one column per label, in the file's units
    (degrees for rotational coordinates when ``in_degrees``).
    Equality compares time, labels, data (NaN equal to NaN) and ``in_degrees``.
    """

    time: np.ndarray
    labels: tuple[str, ...]
    data: np.ndarray
    in_degrees: bool = False
    name: str = ""
    metadata: Mapping[str, str] = attrs.field(factory=dict)
    comments: tuple[str, ...] = ()
    source: Path | None = None
    label_line: int | None = None

    def __attrs_post_init__(self) -> None:
        time = np.asarray(self.time, dtype=float).reshape(-1)
        data = np.asarray(self.data, dtype=float)
        if data.ndim == 1:
            data = data.reshape(-1, 1) if len(self.labels) == 1 else data.reshape(len(time), -1)
        object.__setattr__(self, "time", time)
        object.__setattr__(self, "data", data)
        object.__setattr__(self, "labels", tuple(self.labels))
        if data.shape != (time.shape[0], len(self.labels)):
            raise ValueError(f"data has shape {data.shape}, expected ({time.shape[0]}, {len(self.labels)})")

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Table):
            return NotImplemented
        return (
            self.labels == other.labels
            and self.in_degrees == other.in_degrees
            and _same(self.time, other.time)
            and _same(self.data, other.data)
        )

    __hash__ = None  # type: ignore[assignment]

    # ----- shape ------------------------------------------------------------------------
    @property
    def n_rows(self) -> int:
        return int(self.time.shape[0])

    @property
    def n_columns(self) -> int:
        """Number of data columns (time excluded)."""
        return len(self.labels)

    # ----- columns ----------------------------------------------------------------------
    def has(self, label: str) -> bool:
        return label in self.labels

    def index(self, label: str) -> int:
        """Position of ``label`` among the data columns; :class:`InputError` with close matches if absent."""
        try:
            return self.labels.index(label)
        except ValueError:
            raise self.missing_column(label) from None

    def missing_column(self, label: str) -> InputError:
        close = close_matches(label, self.labels)
        hint = f"; close matches: {', '.join(close)}" if close else ""
        return InputError(
            f"column '{label}' not found{hint}",
            file=self.source,
            line=self.label_line,
            element=f"column '{label}'",
            expected=f"one of the {len(self.labels)} columns of the file",
        )

    def column(self, label: str) -> np.ndarray:
        """Values of one column, shape (n,)."""
        return self.data[:, self.index(label)]

    def columns(self, labels: Sequence[str]) -> np.ndarray:
        """Values of several columns, shape (n, len(labels))."""
        return self.data[:, [self.index(label) for label in labels]] if labels else np.zeros((self.n_rows, 0))

    def select(self, labels: Sequence[str]) -> Table:
        """A table with only ``labels`` (in that order)."""
        return attrs.evolve(self, labels=tuple(labels), data=self.columns(labels))

    def load_column(self, coordinate: str) -> np.ndarray:
        """ID column of ``coordinate``: ``<coordinate>_moment``, ``<coordinate>_force`` or the bare name."""
        for candidate in (coordinate + "_moment", coordinate + "_force", coordinate):
            if candidate in self.labels:
                return self.data[:, self.labels.index(candidate)]
        raise self.missing_column(coordinate + "_moment")

    def coordinate_labels(self) -> tuple[str, ...]:
        """Labels with ``_moment`` / ``_force`` stripped (ID tables)."""
        return tuple(strip_load_suffix(label) for label in self.labels)

    # ----- units ------------------------------------------------------------------------
    def to_radians(self, rotational: Collection[str]) -> Table:
        """Columns named in ``rotational`` converted from degrees, if the file says degrees.

        ``rotational`` is the set of the model's rotational coordinate names. Other columns
        (translations, coupled coordinates) are left as they are. The result has
        ``in_degrees=False``.
        """
        if not self.in_degrees:
            return self
        rot = set(rotational)
        data = self.data.copy()
        for j, label in enumerate(self.labels):
            if label in rot:
                data[:, j] = np.deg2rad(data[:, j])
        return attrs.evolve(self, data=data, in_degrees=False)

    def to_degrees(self, rotational: Collection[str]) -> Table:
        """Inverse of :meth:`to_radians` (for writing IK-style files in degrees)."""
        if self.in_degrees:
            return self
        rot = set(rotational)
        data = self.data.copy()
        for j, label in enumerate(self.labels):
            if label in rot:
                data[:, j] = np.rad2deg(data[:, j])
        return attrs.evolve(self, data=data, in_degrees=True)


# ----- reading ----------------------------------------------------------------------------
def _nan_allowed(policy: NanPolicy | None) -> Callable[[str], bool]:
    if policy is None:
        return lambda label: False
    if callable(policy):
        return policy
    allowed = set(policy)
    return lambda label: label in allowed


def _split_labels(line: str) -> list[str]:
    if "\t" in line:
        return [part.strip() for part in line.split("\t") if part.strip()]
    return line.split()


def read_storage(path: str | os.PathLike[str], *, allow_nan: NanPolicy | None = None) -> Table:
    """Read a ``.sto`` / ``.mot`` file.

    ``allow_nan``: labels (or a predicate on labels) of the columns where NaN is data, e.g.
    GRF centre-of-pressure columns. NaN anywhere else, a row with the wrong number of
    values, text that is not a number, or time that does not increase raise
    :class:`InputError` naming the file, line and column.
    """
    path = Path(path)
    try:
        text = read_text_file(path)
    except OSError as exc:
        raise InputError(
            f"cannot read table: {exc.strerror or exc}", file=path, expected="a readable .sto/.mot file"
        ) from exc
    return parse_storage(text, source=path, allow_nan=allow_nan)


def parse_storage(text: str, *, source: Path | None = None, allow_nan: NanPolicy | None = None) -> Table:
    """Parse the text of a ``.sto`` / ``.mot`` file (see :func:`read_storage`)."""
    lines = text.removeprefix(BOM).splitlines()
    end = next((i for i, line in enumerate(lines) if line.strip().lower() == "endheader"), None)
    if end is None:
        raise InputError(
            "no 'endheader' line: not an OpenSim table",
            file=source,
            expected="an OpenSim .sto/.mot file (header lines, 'endheader', column labels, rows)",
        )
    name = ""
    metadata: dict[str, str] = {}
    comments: list[str] = []
    for i, raw in enumerate(lines[:end]):
        line = raw.strip()
        if "=" in line and not line.startswith('"'):
            key, _, value = line.partition("=")
            metadata[key.strip()] = value.strip()
        elif i == 0 and line:
            name = line
        else:
            comments.append(raw.rstrip())
    while comments and not comments[-1].strip():
        comments.pop()
    in_degrees = _in_degrees(metadata, lines[:end], source)
    label_index = next((i for i in range(end + 1, len(lines)) if lines[i].strip()), None)
    if label_index is None:
        raise InputError(
            "no column labels after 'endheader'", file=source, line=end + 1, expected="a line of column labels"
        )
    header = _split_labels(lines[label_index])
    label_line = label_index + 1
    if len(set(header)) != len(header):
        dup = sorted({h for h in header if header.count(h) > 1})
        raise InputError(
            f"duplicated column label(s): {', '.join(dup)}",
            file=source,
            line=label_line,
            expected="unique column labels",
        )
    width = len(header)
    n_columns = metadata.get("nColumns")
    if n_columns is not None and n_columns.strip().isdigit() and int(n_columns) != width:
        raise InputError(
            f"header says nColumns={n_columns} but the label line has {width} labels",
            file=source,
            line=label_line,
            expected="nColumns equal to the number of labels (time included)",
        )
    rows: list[list[str]] = []
    row_lines: list[int] = []
    for i in range(label_index + 1, len(lines)):
        tokens = lines[i].split()
        if not tokens:
            continue
        if len(tokens) != width:
            _raise_empty_cell(lines[i], header, source, i + 1)
            raise InputError(
                f"row has {len(tokens)} values but there are {width} column labels",
                file=source,
                line=i + 1,
                element=(
                    f"column '{header[len(tokens)]}' (first missing value)"
                    if len(tokens) < width
                    else f"column {width + 1} (after the last label '{header[-1]}')"
                ),
                expected=f"{width} values per row",
            )
        rows.append(tokens)
        row_lines.append(i + 1)
    try:
        values = np.array(rows, dtype=float).reshape(len(rows), width)
    except ValueError:
        _raise_bad_number(rows, row_lines, header, source)
        raise  # unreachable
    labels = tuple(header[1:])
    _check_nan(values, header, row_lines, source, _nan_allowed(allow_nan))
    n_read = values.shape[0]
    values, row_lines = _drop_repeated_rows(values, row_lines, source)
    time = values[:, 0]
    _check_time(time, row_lines, header[0], source)
    n_rows = metadata.get("nRows")
    if n_rows is not None and n_rows.strip().isdigit() and int(n_rows) not in (n_read, len(row_lines)):
        warnings.warn(
            f"{source}: header says nRows={n_rows} but the file has {n_read} rows; using the rows", stacklevel=3
        )
    return Table(
        time=time,
        labels=labels,
        data=values[:, 1:],
        in_degrees=in_degrees,
        name=name,
        metadata=metadata,
        comments=tuple(comments),
        source=source,
        label_line=label_line,
    )


def _in_degrees(metadata: dict[str, str], header: list[str], source: Path | None) -> bool:
    """The ``inDegrees`` header: ``yes`` or ``no`` (any case; missing: no). OpenSim reads
    every other value (``true``, ``1``, ...) as radians without a word, so such a value is
    refused rather than guessed."""
    value = metadata.get("inDegrees")
    if value is None or value.strip().lower() in ("yes", "no"):
        return value is not None and value.strip().lower() == "yes"
    line = next((i + 1 for i, text in enumerate(header) if text.strip().startswith("inDegrees")), None)
    raise InputError(f"inDegrees={value.strip()}: OpenSim reads only 'yes' as degrees and would read this file as "
                     "radians", file=source, line=line, element="inDegrees",
                     expected="inDegrees=yes (angles in degrees) or inDegrees=no (radians)")


def _raise_empty_cell(line: str, header: list[str], source: Path | None, number: int) -> None:
    """An empty cell of a tab-separated row (a gap left by a spreadsheet or an exporter) is
    named by its column: splitting on white space alone would report the row's last
    column as missing."""
    if "\t" not in line:
        return
    cells = line.rstrip("\r\n").split("\t")
    while len(cells) > len(header) and not cells[-1].strip():
        cells.pop()  # trailing tabs
    if len(cells) != len(header):
        return
    empty = [j for j, cell in enumerate(cells) if not cell.strip()]
    if empty:
        names = ", ".join(f"'{header[j]}'" for j in empty[:5]) + (" ..." if len(empty) > 5 else "")
        raise InputError(
            f"empty cell{'s' if len(empty) > 1 else ''} in column{'s' if len(empty) > 1 else ''} {names}",
            file=source,
            line=number,
            element=f"column '{header[empty[0]]}'",
            expected="a number in every cell (write NaN for a gap where it is allowed: the centre-of-pressure "
            "columns of GRF files)",
        )


def _raise_bad_number(rows: list[list[str]], row_lines: list[int], header: list[str], source: Path | None) -> None:
    for tokens, line in zip(rows, row_lines):
        for j, token in enumerate(tokens):
            try:
                float(token)
            except ValueError:
                raise InputError(
                    f"'{token}' is not a number",
                    file=source,
                    line=line,
                    element=f"column '{header[j]}'",
                    expected="a number",
                ) from None


def _check_nan(
    values: np.ndarray, header: list[str], row_lines: list[int], source: Path | None, allowed: Callable[[str], bool]
) -> None:
    infinite = np.isinf(values)
    if infinite.any():  # 'inf' / 'Infinity' parse as numbers but are no data (no column allows them)
        i, j = (int(k) for k in np.argwhere(infinite)[0])
        raise InputError(
            f"infinite value {float(values[i, j])!r} where data must be present",
            file=source,
            line=row_lines[i],
            element=f"column '{header[j]}'",
            expected="a finite number",
        )
    bad = np.isnan(values)
    if not bad.any():
        return
    for j in np.flatnonzero(bad.any(axis=0)):
        if j == 0 or not allowed(header[j]):
            i = int(np.flatnonzero(bad[:, j])[0])
            raise InputError(
                "NaN where data must be present",
                file=source,
                line=row_lines[i],
                element=f"column '{header[j]}'",
                expected="a number (NaN is allowed only in centre-of-pressure columns of GRF files)",
            )


def _drop_repeated_rows(values: np.ndarray, row_lines: list[int], source: Path | None) -> tuple[np.ndarray, list[int]]:
    """Drop a row that repeats the previous row's time with the same values.

    OpenSim's Storage sometimes writes the last state twice; the copies can differ in the
    last printed digit, so values count as the same when they agree to 1e-8 (relative to
    max(1, |value|)). A repeated time with different values is left for the time check.
    """
    if values.shape[0] < 2:
        return values, row_lines
    same_time = values[1:, 0] == values[:-1, 0]
    if not same_time.any():
        return values, row_lines
    a, b = values[1:], values[:-1]
    close = (np.abs(a - b) <= 1e-8 * np.maximum(1.0, np.abs(b))) | (np.isnan(a) & np.isnan(b))
    repeat = same_time & np.all(close, axis=1)
    if not repeat.any():
        return values, row_lines
    keep = np.concatenate([[True], ~repeat])
    dropped = [row_lines[i + 1] for i in np.flatnonzero(repeat)]
    warnings.warn(
        f"{source}: line(s) {', '.join(map(str, dropped))} repeat the previous row's time and values; dropped",
        stacklevel=4,
    )
    return values[keep], [line for line, k in zip(row_lines, keep) if k]


def _check_time(time: np.ndarray, row_lines: list[int], label: str, source: Path | None) -> None:
    if time.size < 2:
        return
    steps = np.diff(time)
    bad = np.flatnonzero(~(steps > 0))
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(
            f"time does not increase: {float(time[i - 1])!r} then {float(time[i])!r}",
            file=source,
            line=row_lines[i],
            element=f"column '{label}'",
            expected="strictly increasing time",
        )


# ----- writing ----------------------------------------------------------------------------
def format_storage(table: Table, *, name: str | None = None) -> str:
    """The text of ``table`` as OpenSim's Storage writes it."""
    out = [name if name is not None else (table.name or "nmsm")]
    out.append("version=1")
    out.append(f"nRows={table.n_rows}")
    out.append(f"nColumns={table.n_columns + 1}")
    out.append(f"inDegrees={'yes' if table.in_degrees else 'no'}")
    for key, value in table.metadata.items():
        if key not in _WRITER_KEYS:
            out.append(f"{key}={value}")
    out.extend(table.comments)
    out.append("endheader")
    out.append("\t".join(("time", *table.labels)))
    block = np.column_stack([table.time, table.data]) if table.n_rows else np.zeros((0, table.n_columns + 1))
    for row in block.tolist():
        out.append("\t".join(repr(v) if math.isfinite(v) else full_precision(v) for v in row))
    return "\n".join(out) + "\n"


def write_storage(path: str | os.PathLike[str], table: Table, *, name: str | None = None) -> Path:
    """Write ``table`` to ``path`` (``.sto`` or ``.mot``); the name line defaults to the table's name or the file stem."""
    path = Path(path)
    label = name if name is not None else (table.name or path.stem)
    path.write_text(format_storage(table, name=label), encoding="utf-8")
    return path


def table_from_columns(
    time: Sequence[float] | np.ndarray,
    columns: Mapping[str, Sequence[float] | np.ndarray],
    *,
    in_degrees: bool = False,
    name: str = "",
) -> Table:
    """A :class:`Table` from a time vector (n,) and ``label -> values (n,)``."""
    labels = tuple(columns)
    data = (
        np.column_stack([np.asarray(columns[k], dtype=float) for k in labels]) if labels else np.zeros((len(time), 0))
    )
    return Table(time=np.asarray(time, dtype=float), labels=labels, data=data, in_degrees=in_degrees, name=name)

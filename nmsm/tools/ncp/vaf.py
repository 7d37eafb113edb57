"""How many synergies? Variance accounted for by NMF with 1..N synergies.

Users pick the number of synergies of a group as the smallest count whose NMF of the
group's MTP activations accounts for 90-95 % of their variance. :func:`vaf_curve` runs
the factorization for each count; :func:`read_activation_trials` gathers activations of
several trials (``.sto`` files or folders of them) into one (samples, muscles) array.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.text import read_text_file
from nmsm.tools.ncp.nmf import nmf

#: the thresholds the NMSM Pipeline recommends (fractions)
DEFAULT_THRESHOLDS = (0.90, 0.95)
#: activations (dimensionless, 0..1) at or above ``-NEGATIVE_TOLERANCE`` but below 0 are a
#: solver's bound tolerance (NCP's combined activations reach -0.004): set to 0; lower ones
#: are refused (NMF factors non-negative data)
NEGATIVE_TOLERANCE = 0.01
#: clipped values below ``-ROUND_OFF`` are reported in a warning
ROUND_OFF = 1e-9


@attrs.frozen
class VafCurve:
    """VAF (fraction) of the best NMF with ``counts[i]`` synergies, for ``muscles``."""

    muscles: tuple[str, ...]
    counts: tuple[int, ...]
    vaf: tuple[float, ...]
    name: str = ""

    def smallest_count(self, threshold: float) -> int | None:
        """Fewest synergies reaching ``threshold`` (fraction), or None if none does."""
        for count, value in zip(self.counts, self.vaf):
            if value >= threshold:
                return count
        return None

    def table(self, thresholds: Sequence[float] = DEFAULT_THRESHOLDS) -> str:
        """Plain-text table: synergies, VAF %, and the recommendation per threshold."""
        title = f"{self.name}: " if self.name else ""
        lines = [f"{title}{len(self.muscles)} muscles", f"{'synergies':>9}  {'VAF %':>7}"]
        for count, value in zip(self.counts, self.vaf):
            lines.append(f"{count:>9d}  {100 * value:7.2f}")
        for threshold in thresholds:
            best = self.smallest_count(threshold)
            lines.append(
                f"smallest count with VAF >= {100 * threshold:g} %: "
                + (str(best) if best is not None else f"none up to {self.counts[-1]}")
            )
        return "\n".join(lines)


def vaf_curve(
    activations: np.ndarray,
    max_synergies: int | None = None,
    *,
    muscles: Sequence[str] | None = None,
    name: str = "",
    n_starts: int = 10,
    seed: int = 0,
) -> VafCurve:
    """VAF of NMF with 1..``max_synergies`` synergies of ``activations`` (samples, muscles).

    ``max_synergies`` defaults to min(muscles, 10) and is capped at the number of muscles.
    """
    data = np.asarray(activations, dtype=float)
    if data.ndim != 2 or data.shape[1] == 0 or data.shape[0] == 0:
        raise ValueError(f"activations must be a non-empty (samples, muscles) array, got shape {data.shape}")
    if np.any(data < -NEGATIVE_TOLERANCE):
        i, j = np.argwhere(data < -NEGATIVE_TOLERANCE)[0]
        raise InputError(f"activation {data[i, j]:g} at sample {i + 1}, muscle {j + 1} is negative",
                         element="activations", expected=f"activations >= 0 (NMF; down to -{NEGATIVE_TOLERANCE:g} "
                         "is taken for 0)")
    data = np.maximum(data, 0.0)
    n_muscles = data.shape[1]
    top = min(n_muscles, 10) if max_synergies is None else min(int(max_synergies), n_muscles)
    if top < 1:
        raise ValueError("max_synergies must be >= 1")
    names = tuple(muscles) if muscles is not None else tuple(f"muscle_{i + 1}" for i in range(n_muscles))
    counts = tuple(range(1, top + 1))
    values = tuple(nmf(data, k, n_starts=n_starts, seed=seed).vaf for k in counts)
    return VafCurve(muscles=names, counts=counts, vaf=values, name=name)


def activation_files(paths: Iterable[str | os.PathLike[str]]) -> list[Path]:
    """``.sto``/``.mot`` files named by ``paths`` (files, or folders whose tables are taken in name order)."""
    files: list[Path] = []
    for raw in paths:
        path = Path(raw)
        if path.is_dir():
            found = sorted(p for p in path.iterdir() if p.suffix.lower() in (".sto", ".mot"))
            if not found:
                raise InputError("folder holds no .sto files", file=path, expected="MTP muscleActivations/*.sto files")
            files.extend(found)
        elif path.is_file():
            files.append(path)
        else:
            raise InputError("no such file or folder", file=path, expected="an activation .sto file or a folder of them")
    return files


def read_activation_trials(
    paths: Iterable[str | os.PathLike[str]], muscles: Sequence[str] | None = None
) -> tuple[np.ndarray, tuple[str, ...]]:
    """Stack activation tables row-wise: (sum of frames, muscles) and the muscle names.

    ``muscles`` selects and orders columns (default: the first file's columns, which every
    other file must contain). A missing column raises :class:`InputError` naming the file.
    """
    from nmsm.io.storage import read_storage

    files = activation_files(paths)
    blocks = []
    names: tuple[str, ...] | None = tuple(muscles) if muscles is not None else None
    for path in files:
        table = read_storage(path)
        if names is None:
            names = table.labels
        blocks.append(non_negative(table.columns(list(names)), names, table.time, path, table.label_line))
    assert names is not None
    return np.vstack(blocks), names


def _row_line(path: Path, label_line: int | None, row: int, time: float) -> int | None:
    """The 1-based line of data row ``row`` (0-based) of the table file ``path`` whose labels
    are on ``label_line``, when its time reads ``time`` (else None: rows were dropped)."""
    if label_line is None:
        return None
    lines = read_text_file(path, warn=False).splitlines()  # as the table reader decoded it
    seen = -1
    for number in range(label_line + 1, len(lines) + 1):
        tokens = lines[number - 1].split()
        if not tokens:
            continue
        seen += 1
        if seen == row:
            try:
                return number if abs(float(tokens[0]) - time) <= 1e-9 * max(1.0, abs(time)) else None
            except ValueError:
                return None
    return None


def non_negative(block: np.ndarray, names: Sequence[str], time: np.ndarray, path: Path,
                 label_line: int | None = None) -> np.ndarray:
    """``block`` ``(frames, muscles)`` of the file ``path`` with negatives down to
    :data:`NEGATIVE_TOLERANCE` set to 0 (a warning names the file when one is below
    -:data:`ROUND_OFF`); a lower value raises :class:`InputError` naming the file, its line
    (``label_line``: the line of the column labels), data row, time and column."""
    bad = np.argwhere(block < -NEGATIVE_TOLERANCE)
    if bad.size:
        i, j = bad[0]
        more = f"; {len(bad) - 1} more value(s) below -{NEGATIVE_TOLERANCE:g}" if len(bad) > 1 else ""
        raise InputError(f"negative activation {block[i, j]:g} in data row {i + 1} (time {time[i]:g} s){more}",
                         file=path, line=_row_line(path, label_line, int(i), float(time[i])),
                         element=f"column '{names[j]}'",
                         expected=f"activations >= 0 (NMF factors non-negative data; down to -{NEGATIVE_TOLERANCE:g} "
                         "is taken for 0)")
    if block.size and block.min() < -ROUND_OFF:
        i, j = np.unravel_index(int(np.argmin(block)), block.shape)
        warnings.warn(f"{path}: {int(np.sum(block < 0))} slightly negative activation(s), the lowest "
                      f"{block[i, j]:.3g} ('{names[j]}', time {time[i]:g} s), set to 0", stacklevel=3)
    return np.maximum(block, 0.0)

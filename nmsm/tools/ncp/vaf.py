"""How many synergies? Variance accounted for by NMF with 1..N synergies.

Users pick the number of synergies of a group as the smallest count whose NMF of the
group's MTP activations accounts for 90-95 % of their variance. :func:`vaf_curve` runs
the factorization for each count; :func:`read_activation_trials` gathers activations of
several trials (``.sto`` files or folders of them) into one (samples, muscles) array.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.tools.ncp.nmf import nmf

#: the thresholds the NMSM Pipeline recommends (fractions)
DEFAULT_THRESHOLDS = (0.90, 0.95)


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
        blocks.append(table.columns(list(names)))
    assert names is not None
    return np.vstack(blocks), names

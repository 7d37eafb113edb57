"""Array helpers shared by the MTP / SynX terms (CasADi MX, trials stacked on rows)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as cs
import numpy as np


def columns(x: Any, indices: Sequence[int]) -> Any:
    """Columns ``indices`` of an MX/DM matrix, in that order."""
    idx = list(indices)
    if not idx:
        return cs.MX(x.shape[0], 0)
    return cs.horzcat(*[x[:, i] for i in idx])


def mean_rows(x: Any) -> Any:
    """Mean over rows: ``(1, k)``."""
    return cs.sum1(x) / x.shape[0]


def mean_of_trials(blocks: Sequence[Any]) -> Any:
    """Elementwise mean of equally shaped per-trial blocks (n_frames, k)."""
    total = blocks[0]
    for b in blocks[1:]:
        total = total + b
    return total / len(blocks)


def minus_mean(x: Any) -> Any:
    """``x - mean(x)`` for a row or column vector (the original's ``calcMeanDifference2D``)."""
    n = int(x.numel())
    return x - cs.sum1(cs.vec(x)) / n if n else x


def as_dm(values: Sequence[np.ndarray]) -> list[Any]:
    return [cs.DM(np.asarray(v, dtype=float)) for v in values]

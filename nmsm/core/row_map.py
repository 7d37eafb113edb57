"""A per-point CasADi function evaluated on every row of sampled inputs (one row a sample)."""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np


def map_rows(function: cs.Function, *row_matrices: Any, parallel: int = 1) -> list[cs.MX]:
    """Evaluate a per-point function on every row of ``(n, m_i)`` inputs.

    ``function`` takes column vectors; an input of one row is used for every row. The result
    is one ``(n, k_j)`` MX per output. With ``parallel > 1`` the map uses CasADi's thread
    parallelization.
    """
    mats = [cs.DM(np.atleast_2d(m)) if isinstance(m, np.ndarray) else m for m in row_matrices]
    n = max((m.shape[0] for m in mats), default=0)
    cols = []
    for mat in mats:
        rows = mat.shape[0]
        if rows not in (n, 1):
            raise ValueError(f"map_rows: inputs have {rows} and {n} rows")
        col = mat.T
        cols.append(col if rows == n else cs.repmat(col, 1, n))
    mapped = function.map(n, "thread", parallel) if parallel > 1 and n > 1 else function.map(n)
    outs = mapped.call(cols)
    return [cs.MX(o).T for o in outs]

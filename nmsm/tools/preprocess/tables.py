"""Input tables read as the original reads them (OpenSim ``Storage``).

OpenSim's ``Storage`` keeps the first ``nRows`` rows when an old-style header states fewer
rows than the file holds; the tutorial's raw EMG (``GaitTrial48_EMG.mot``: ``nRows=4000``,
4001 rows) depends on it: the sampling rate ``n / (t_end - t_0)`` and the filters' edges
change with the extra row (docs/preprocess.md). Sources may also be tables already in memory.
"""

from __future__ import annotations

import os
import warnings

import attrs

from nmsm.io.storage import NanPolicy, Table, read_storage


def read_table(source: str | os.PathLike[str] | Table, *, allow_nan: NanPolicy | None = None) -> Table:
    """The table of ``source`` (path or :class:`Table`), cut to the header's ``nRows`` like OpenSim."""
    if isinstance(source, Table):
        return source
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*header says nRows=.*")
        table = read_storage(source, allow_nan=allow_nan)
    stated = str(table.metadata.get("nRows", "")).strip()
    if stated.isdigit() and 0 < int(stated) < table.n_rows:
        n = int(stated)
        warnings.warn(f"{table.source}: header says nRows={n}, file has {table.n_rows} rows; using the first {n} "
                      "as OpenSim's Storage (and so the original) does", stacklevel=2)
        table = attrs.evolve(table, time=table.time[:n], data=table.data[:n])
    return table

__all__ = ["read_table"]

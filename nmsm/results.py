"""Results folders as pandas DataFrames: ``nmsm.results.load(DIR)``.

Needs pandas (``pip install "nmsm[pandas]"``). Every OpenSim table (``.sto``, ``.mot``) of
the folder and its sub-folders becomes one DataFrame, keyed by its path relative to the
folder (``"IKData/arm1.sto"``); earlier runs' files (``superseded/``) and hidden folders
are left out. Each DataFrame's index is the file's ``time`` column (s; for tables that are
not time series, such as ``synergyWeights.sto``, the row number the file holds there) and
its columns the file's labels, values in the file's units; ``df.attrs`` holds ``"file"``
(the path), ``"in_degrees"`` and ``"header"`` (the header's ``key=value`` lines).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from nmsm.errors import InputError

if TYPE_CHECKING:
    import pandas

TABLE_SUFFIXES = (".sto", ".mot")
#: sub-folders of a results folder that hold other runs' files
SKIPPED_FOLDERS = ("superseded",)


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as exc:
        raise ImportError('nmsm.results.load needs pandas: pip install "nmsm[pandas]"') from exc
    return pandas


def table_files(directory: str | os.PathLike[str]) -> list[Path]:
    """The OpenSim table files of a results folder, sorted by relative path (see the module)."""
    root = Path(directory)
    if not root.is_dir():
        raise InputError("not a results folder", file=root, expected="a folder written by an nmsm tool")
    found = []
    for path in sorted(root.rglob("*")):
        parts = path.relative_to(root).parts
        if any(p.startswith(".") for p in parts) or any(p in SKIPPED_FOLDERS for p in parts[:-1]):
            continue
        if path.is_file() and path.suffix.lower() in TABLE_SUFFIXES:
            found.append(path)
    return found


def load_table(path: str | os.PathLike[str]) -> pandas.DataFrame:
    """One OpenSim table as a DataFrame (index ``time``; see the module for ``attrs``)."""
    from nmsm.io.storage import read_storage

    pd = _pandas()
    table = read_storage(path, allow_nan=lambda label: True)
    frame = pd.DataFrame(table.data, index=pd.Index(table.time, name="time"), columns=list(table.labels))
    frame.attrs.update({"file": str(path), "in_degrees": table.in_degrees, "header": dict(table.metadata)})
    return frame


def load(directory: str | os.PathLike[str]) -> dict[str, pandas.DataFrame]:
    """Every table of a results folder: relative path (POSIX form) -> DataFrame."""
    root = Path(directory)
    return {path.relative_to(root).as_posix(): load_table(path) for path in table_files(root)}

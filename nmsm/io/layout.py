"""The tools' data-folder layout (docs/guide.md, section 2) as the results-folder checks need it.

A data folder holds one sub-folder per kind of trial table: ``IKData/<trial>.sto``,
``IDData``, ``EMGData``, ``GRFData`` and ``MAData/<trial>/``. Results must not be written
into the data folder itself or into (or below) one of those sub-folders: the next run would
read them as trials (:class:`nmsm.core.results.ResultsDirectory`).
"""

from __future__ import annotations

import os
from pathlib import Path

#: sub-folders of a data folder, one per kind of trial table
TRIAL_FOLDERS = ("IKData", "IDData", "EMGData", "GRFData", "MAData")


def trial_table_folders(data_directory: str | os.PathLike[str], label: str = "data") -> dict[str, Path]:
    """``{description: folder}`` of the trial sub-folders of ``data_directory`` (whether or
    not they exist), for ``ResultsDirectory(input_folders=...)``."""
    root = Path(data_directory)
    return {f"{label} {name}": root / name for name in TRIAL_FOLDERS}

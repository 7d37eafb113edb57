"""Every file format nmsm reads and writes.

* :mod:`nmsm.io.trc`      marker files (``MarkerTable``, metres, NaN gaps)
* :mod:`nmsm.io.storage`  ``.sto`` / ``.mot`` tables (``Table``, degrees converted per coordinate)
* :mod:`nmsm.io.trials`   trial files by prefix (exact name first, unique substring else)
* :mod:`nmsm.io.osimx`    ``.osimx`` personalized-model files
* :mod:`nmsm.io.paths`    paths written in settings files
* :mod:`nmsm.io.settings` settings XML of every tool (upgrade of old schemas, templates)

Importing this package imports neither CasADi nor OpenSim.
"""

from __future__ import annotations

from nmsm.io.osimx import (
    GcpSpring,
    OsimxContactSurface,
    OsimxModel,
    OsimxMuscle,
    OsimxSynergy,
    read_osimx,
    write_osimx,
)
from nmsm.io.paths import resolve_path
from nmsm.io.storage import Table, read_storage, strip_load_suffix, table_from_columns, write_storage
from nmsm.io.trc import MarkerTable, read_trc, write_trc
from nmsm.io.trials import find_file_by_suffix, find_trial_file, find_trial_folder, trial_prefixes

__all__ = [
    "GcpSpring",
    "MarkerTable",
    "OsimxContactSurface",
    "OsimxModel",
    "OsimxMuscle",
    "OsimxSynergy",
    "Table",
    "find_file_by_suffix",
    "find_trial_file",
    "find_trial_folder",
    "read_osimx",
    "read_storage",
    "read_trc",
    "resolve_path",
    "strip_load_suffix",
    "table_from_columns",
    "trial_prefixes",
    "write_osimx",
    "write_storage",
    "write_trc",
]

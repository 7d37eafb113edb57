"""Muscle-tendon velocity from muscle-tendon length (the original's ``createMuscleTendonVelocity``).

Lengths (m) are low-passed (Butterworth order 4, ``cutoff`` Hz, zero phase) and
differentiated through the natural quintic (GCV) spline; the result (m/s) is written next
to the length file as ``<name>_Velocity.sto`` (``<name>_Length.sto`` -> ``<name>_Velocity.sto``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage, table_from_columns, write_storage
from nmsm.model.signal import quintic_spline
from nmsm.tools.preprocess.signals import lowpass


def muscle_tendon_velocity(lengths: Table, cutoff: float | None = 10.0) -> Table:
    """Velocities (m/s) of every column of a muscle-tendon length table (m)."""
    data = lengths.data if cutoff is None else lowpass(lengths.time, lengths.data, cutoff)
    _, velocity, _ = quintic_spline(lengths.time, data, lengths.time)
    return table_from_columns(lengths.time, {label: velocity[:, i] for i, label in enumerate(lengths.labels)},
                              name="MuscleAnalysis_Velocity")


def create_velocity_file(length_file: str | os.PathLike[str], cutoff: float | None = 10.0) -> Path:
    """Write ``*_Velocity.sto`` next to ``*_Length.sto``; returns its path."""
    path = Path(length_file)
    if "_Length" not in path.stem:
        raise InputError("not a muscle-tendon length file", file=path, expected="a file named '*_Length.sto'")
    table = read_storage(path)
    out = path.with_name(path.stem.replace("_Length", "_Velocity") + path.suffix)
    velocity = muscle_tendon_velocity(table, cutoff)
    if not np.all(np.isfinite(velocity.data)):
        raise InputError("non-finite velocities", file=path, expected="finite muscle-tendon lengths")
    return write_storage(out, velocity)

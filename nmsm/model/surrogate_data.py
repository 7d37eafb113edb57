"""Geometry samples read from a surrogate data folder.

Layout (the original's ``surrogate_model_data_directory``)::

    <data>/IKData/<trial>.sto                        poses (one file per trial)
    <data>/MAData/<trial>/*_Length.sto               muscle-tendon lengths (m)
    <data>/MAData/<trial>/*_MomentArm_<coord>.sto    moment arms (m), one per surrogate coordinate

Rows of every trial are stacked. IK columns of rotational coordinates are converted
from degrees when the file says ``inDegrees=yes`` (an IK file whose header looks wrong for
the model warns: :mod:`nmsm.io.motion_units`); length and moment-arm files are read as they
are. Time columns must agree between a trial's files.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from nmsm.errors import InputError
from nmsm.io.motion_units import Rotational, warn_implausible_angles
from nmsm.io.storage import read_storage
from nmsm.io.trials import find_file_by_suffix, find_trial_file, find_trial_folder, trial_prefixes
from nmsm.model.surrogate import GeometrySamples


def _same_time(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.allclose(a, b, rtol=0, atol=1e-6))


def read_trial_samples(
    data_directory: str | os.PathLike[str],
    trial: str,
    coordinates: Sequence[str],
    rotational: Rotational,
    muscles: Sequence[str] | None = None,
) -> GeometrySamples:
    """One trial's samples (see the module docstring). ``rotational``: the model's rotational
    coordinates, or name -> range (rad) for the unit check; ``muscles`` default: the Length
    file's columns."""
    data = Path(data_directory)
    ik_file = find_trial_file(data / "IKData", trial)
    ik = read_storage(ik_file)
    warn_implausible_angles(ik, rotational, file=ik_file)
    ik = ik.to_radians(rotational)
    folder = find_trial_folder(data / "MAData", trial)
    length = read_storage(find_file_by_suffix(folder, "_Length"))
    names = tuple(length.labels if muscles is None else muscles)
    if not _same_time(ik.time, length.time):
        raise InputError(
            f"{length.n_rows} length rows do not match the {ik.n_rows} poses of {ik_file.name} (times differ)",
            file=length.source,
            element="time",
            expected="the same time column as the IK file",
        )
    arms = np.zeros((ik.n_rows, len(names), len(coordinates)))
    for k, coord in enumerate(coordinates):
        table = read_storage(find_file_by_suffix(folder, f"_MomentArm_{coord}"))
        if not _same_time(ik.time, table.time):
            raise InputError("moment-arm rows do not match the IK poses (times differ)", file=table.source,
                             element="time", expected=f"the time column of {ik_file.name}")
        arms[:, :, k] = table.columns(names)
    return GeometrySamples(coordinates, names, ik.columns(coordinates), length.columns(names), arms)


def read_samples(
    data_directory: str | os.PathLike[str],
    coordinates: Sequence[str],
    rotational: Rotational,
    trials: Sequence[str] | None = None,
    muscles: Sequence[str] | None = None,
) -> GeometrySamples:
    """All trials' samples stacked (trials default: every table in ``IKData``)."""
    data = Path(data_directory)
    prefixes = list(trials) if trials else trial_prefixes(data / "IKData")
    if not prefixes:
        raise InputError("no trial in IKData", file=data / "IKData", expected="one .sto/.mot file of poses per trial")
    parts = [read_trial_samples(data, t, coordinates, rotational, muscles) for t in prefixes]
    first = parts[0]
    for p in parts[1:]:
        if p.muscles != first.muscles:
            raise InputError("trials have different muscle columns", file=data / "MAData",
                             expected=f"the muscles {', '.join(first.muscles)} in every Length file")
    return GeometrySamples(
        first.coordinates,
        first.muscles,
        np.vstack([p.q for p in parts]),
        np.vstack([p.lengths for p in parts]),
        np.concatenate([p.moment_arms for p in parts], axis=0),
    )

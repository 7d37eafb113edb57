"""The surrogate a controller's settings describe: fitted from a surrogate data folder, or loaded.

:func:`surrogate_from_settings`: with ``load_surrogate_model`` and an existing model file
it loads it (checking that it covers the coordinate list), else it fits from the data
folder (:mod:`nmsm.model.surrogate_data`); with ``save_surrogate_model`` it writes the
model. Fitting holds out a random fifth of the poses to measure accuracy (stored in the
model) and fits on the rest. :func:`load_surrogate` does the same from a controller's
settings values and keeps each fit for the process.

The original keeps the fitted model in ``surrogateMuscles.mat`` in MATLAB's current
folder (MATLAB function handles). nmsm keeps it as JSON next to the settings file: the
file name's extension is replaced by ``.json`` (``surrogateMuscles.json``,
:func:`surrogate_model_path`).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs

from nmsm.errors import InputError
from nmsm.model.surrogate import SurrogateModel, fit_surrogate_model
from nmsm.model.surrogate_data import read_samples

#: share of the sample poses held out to measure a new surrogate's accuracy
HOLDOUT_FRACTION = 0.2
#: the original's default ``<surrogate_model_file_name>``
DEFAULT_FILE_NAME = "surrogateMuscles.mat"


def surrogate_model_path(settings_file: str | os.PathLike[str] | None, file_name: str = DEFAULT_FILE_NAME) -> Path:
    """Where a ``<surrogate_model_file_name>`` is kept: next to the settings file (the current
    folder without one), as JSON (the name's extension replaced by ``.json``; Windows
    separators accepted)."""
    base = Path(settings_file).resolve().parent if settings_file else Path.cwd()
    return (base / Path(file_name.replace("\\", "/")).with_suffix(".json")).resolve()


@attrs.frozen
class SurrogateSettings:
    """Where the samples are, what to fit, and where the fitted model is kept."""

    model_file: Path
    data_directory: Path
    coordinates: tuple[str, ...]
    epsilon: float = 1e-4
    degree: int = 5
    load: bool = False
    save: bool = False
    model_path: Path = Path("surrogateMuscles.json")
    settings_file: Path | None = None


def rotational_coordinates(model_file: str | os.PathLike[str]) -> set[str]:
    """Names of the model's rotational coordinates (for degree conversion)."""
    from nmsm.model import load_model

    return {c.name for c in load_model(model_file).coordinates if c.is_rotational}


def fit_from_data_directory(
    model_file: str | os.PathLike[str],
    data_directory: str | os.PathLike[str],
    coordinates: Sequence[str],
    *,
    degree: int = 5,
    epsilon: float = 1e-4,
    trials: Sequence[str] | None = None,
    muscles: Sequence[str] | None = None,
    holdout_fraction: float = HOLDOUT_FRACTION,
    seed: int | None = 0,
) -> SurrogateModel:
    """Fit a surrogate to the samples of a surrogate data folder (IKData + MAData).

    ``coordinates`` and ``muscles`` (default: every muscle of the Length files) are checked
    against the model first: :class:`InputError` naming the unknown names, the model and
    close matches.
    """
    from nmsm.model import load_model
    from nmsm.model.muscle_analysis import check_model_names

    model = load_model(model_file)
    described = f"{model.name} ({model_file})"
    check_model_names("coordinates", coordinates, model.coordinate_names, described)
    if muscles is not None:
        check_model_names("muscles", muscles, model.muscle_names, described)
    rotational = {c.name: c.range for c in model.coordinates if c.is_rotational}  # ranges: the IK unit check
    samples = read_samples(data_directory, coordinates, rotational, trials, muscles)
    meta = {"model_file": str(Path(model_file).resolve()), "data_directory": str(Path(data_directory).resolve()),
            "moment_arms": "MuscleAnalysis files"}
    return fit_surrogate_model(samples, degree, epsilon, holdout_fraction=holdout_fraction, seed=seed, metadata=meta)


def check_covers(model: SurrogateModel, coordinates: Sequence[str], path: Path) -> None:
    """:class:`InputError` unless the loaded model was fitted on ``coordinates``."""
    if tuple(model.coordinates) != tuple(coordinates):
        raise InputError(
            f"the saved surrogate was fitted on coordinates {' '.join(model.coordinates)}",
            file=path,
            element="coordinates",
            expected=f"a surrogate of {' '.join(coordinates)} (delete the file or set load_surrogate_model false)",
        )


def surrogate_from_settings(settings: SurrogateSettings) -> SurrogateModel:
    """Load or fit the surrogate the settings describe; save it when asked."""
    path = settings.model_path
    if settings.load and path.is_file():
        model = SurrogateModel.load(path)
        check_covers(model, settings.coordinates, path)
        return model
    if settings.load:
        warnings.warn(f"load_surrogate_model is true but {path} does not exist; fitting a new surrogate", stacklevel=2)
    model = fit_from_data_directory(settings.model_file, settings.data_directory, settings.coordinates,
                                    degree=settings.degree, epsilon=settings.epsilon)
    if settings.save:
        model.save(path)
    return model



_SURROGATE_CACHE: dict[tuple[Any, ...], SurrogateModel] = {}


def load_surrogate(model_file: os.PathLike[str] | str, data_directory: os.PathLike[str] | str,
                   coordinates: Sequence[str], *, degree: int, epsilon: float, load: bool = False,
                   save: bool = False, settings_file: os.PathLike[str] | str | None = None,
                   file_name: str = DEFAULT_FILE_NAME) -> SurrogateModel:
    """Fit (or load/save, as the settings ask) the surrogate of a muscle or synergy controller;
    fits are cached per process (same data, coordinates, degree and epsilon). ``file_name``:
    the settings' ``<surrogate_model_file_name>``, kept as JSON next to the settings file
    (:func:`surrogate_model_path`)."""
    key = (str(Path(model_file).resolve()), str(Path(data_directory).resolve()), tuple(coordinates), degree, epsilon)
    if key in _SURROGATE_CACHE and not (load or save):
        return _SURROGATE_CACHE[key]
    settings = SurrogateSettings(model_file=Path(model_file), data_directory=Path(data_directory),
                                 coordinates=tuple(coordinates), epsilon=epsilon, degree=degree, load=load, save=save,
                                 model_path=surrogate_model_path(settings_file, file_name),
                                 settings_file=Path(settings_file) if settings_file else None)
    model = surrogate_from_settings(settings)
    _SURROGATE_CACHE[key] = model
    return model

"""Surrogate Model Creation: fit, load or save a surrogate as the settings ask.

:func:`surrogate_from_settings` is what Treatment Optimization calls: with
``load_surrogate_model`` and an existing model file it loads it (checking that it covers
the coordinate list), else it fits from the data folder; with ``save_surrogate_model``
it writes the model. Fitting holds out a random fifth of the poses to measure accuracy
(stored in the model) and fits on the rest.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path

from nmsm.errors import InputError
from nmsm.model.surrogate import SurrogateModel, fit_surrogate_model
from nmsm.tools.surrogate.data import read_samples
from nmsm.tools.surrogate.settings import SurrogateSettings

#: share of the sample poses held out to measure a new surrogate's accuracy
HOLDOUT_FRACTION = 0.2


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


def accuracy_report(model: SurrogateModel) -> str:
    """A table of each muscle's held-out accuracy (mm), worst muscle last line."""
    lines = [f"{'muscle':<16s} {'coords':>6s} {'L rms':>8s} {'L max':>8s} {'r rms':>8s} {'r max':>8s}   (mm, held-out poses)"]
    worst: tuple[float, str] | None = None
    for m in model.muscles:
        a = m.accuracy
        if a is None:
            lines.append(f"{m.muscle:<16s} {len(m.coordinates):>6d}   (no held-out poses)")
            continue
        lines.append(f"{m.muscle:<16s} {len(m.coordinates):>6d} {a.length_rms * 1e3:8.3f} {a.length_max * 1e3:8.3f} "
                     f"{a.worst_moment_arm_rms * 1e3:8.3f} {a.worst_moment_arm_max * 1e3:8.3f}")
        score = max(a.length_rms / 0.5e-3, a.worst_moment_arm_rms / 1e-3)
        if worst is None or score > worst[0]:
            worst = (score, m.muscle)
    if model.excluded_muscles:
        lines.append(f"not modeled (no moment arm > {model.epsilon:g} m): {', '.join(model.excluded_muscles)}")
    if worst is not None:
        lines.append(f"worst muscle: {worst[1]}")
    return "\n".join(lines)


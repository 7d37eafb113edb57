"""The surrogate-data stage (``<SurrogateDataTool>``): Latin-hypercube poses around a
reference motion (:func:`nmsm.model.surrogate_sampling.latin_hypercube_poses`, clipped to
clamped coordinate ranges) and their muscle analysis
(:func:`nmsm.model.muscle_analysis.analyze_motion`: exact path geometry; OpenSim through
the bridge only for muscles with active wrapping), written in the surrogate data layout::

    <results>/IKData/<trial>.sto            the poses (rad; one row per sample, 1 ms apart)
    <results>/MAData/<trial>/<trial>_Length.sto, _MomentArm_<coordinate>.sto, _Velocity.sto

Treatment Optimization's synergy controller fits its polynomial surrogate to this folder
(``surrogate_model_data_directory``).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.console import announce
from nmsm.core.results import ResultsDirectory
from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage, write_storage
from nmsm.io.trials import find_trial_file
from nmsm.tools.pipeline.native import read_native_settings
from nmsm.tools.pipeline.surrogate_settings import TOOL, SurrogateDataSettings


def read_settings(path: str | os.PathLike[str]) -> SurrogateDataSettings:
    return read_native_settings(path, SurrogateDataSettings, TOOL)


def sample_poses(model, reference: np.ndarray, settings: SurrogateDataSettings) -> np.ndarray:
    """All coordinates ``(n_samples, n)`` (model order, rad/m): the sampled coordinates drawn
    around every ``frame_stride``-th reference frame, the others at the reference."""
    from nmsm.model.surrogate_sampling import coordinate_padding, latin_hypercube_poses

    names = model.coordinate_names
    index = [names.index(c) for c in settings.coordinate_list]
    coordinates = [model.coordinate(c) for c in settings.coordinate_list]
    lower, upper = coordinate_padding(settings.coordinate_list, [c.motion_type == "rotational" for c in coordinates],
                                      np.radians(settings.angular_padding), settings.linear_padding)
    low = np.array([c.range[0] if c.clamped else -np.inf for c in coordinates])
    high = np.array([c.range[1] if c.clamped else np.inf for c in coordinates])
    frames = reference[::settings.frame_stride]
    sampled = latin_hypercube_poses(frames[:, index], lower, upper, low, high, settings.samples_per_frame,
                                    settings.seed)
    poses = np.repeat(frames, settings.samples_per_frame, axis=0)
    poses[:, index] = sampled
    return poses


def run_settings(settings_file: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
                 **options: Any) -> Path:
    """Run the stage of a ``<SurrogateDataTool>`` settings file; returns the output folder."""
    from nmsm.model.muscle_analysis import analyze_motion, motion_poses
    from nmsm.model.osim import load_model

    settings = read_settings(settings_file)
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    model = load_model(settings.input_model_file)
    unknown = [c for c in settings.coordinate_list if c not in model.coordinate_names]
    if unknown:
        raise InputError(f"coordinates not in the model: {', '.join(unknown)}", file=settings_file,
                         element="<coordinate_list>", expected=f"coordinates of {settings.input_model_file}")
    motion_file = find_trial_file(settings.data_directory / "IKData", settings.trial_name)
    reference = motion_poses(model, read_storage(motion_file))
    poses = sample_poses(model, reference, settings)
    announce("surrogate", settings=settings_file, model=settings.input_model_file, trials=[settings.trial_name],
             problem=f"{poses.shape[0]} poses ({settings.samples_per_frame} per frame) varying "
                     f"{len(settings.coordinate_list)} coordinates")
    time = 1e-3 * np.arange(poses.shape[0])
    table = Table(time=time, labels=tuple(model.coordinate_names), data=poses, name="surrogate poses")
    results = ResultsDirectory(settings.results_directory, inputs=[settings.input_model_file])
    with results.task("samples") as stage:
        (stage / "IKData").mkdir()
        write_storage(stage / "IKData" / f"{settings.trial_name}.sto", table, name="Coordinates")
        geometry = analyze_motion(settings.input_model_file, table, model=model,
                                  coordinates=settings.coordinate_list)
        geometry.write(stage / "MAData", settings.trial_name)
    results.copy_in(settings_file, f"settings_{Path(settings_file).name}")
    return results.path

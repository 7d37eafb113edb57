"""The preprocessing stage: full-length trials cut into the personalization tools' trials
(``<DataPreprocessingTool>``, tools.md §2: ``processRawEmgFile`` and ``splitIntoTrials``),
done by :mod:`nmsm.tools.preprocess`.

Per full-length trial ``<name>`` and each time window ``k`` (output trial ``<name>_<k>``):

* EMG (``EMGData/<name>.sto``, raw): :func:`nmsm.tools.preprocess.run.process_emg_table`
  with each channel's own mean and minimum (``emg_demean`` ``channel``, the default; ``frame``
  is the original's across-channel form): 4th-order Butterworth
  high-pass (40 Hz) with zero phase (MATLAB ``filtfilt``), channel mean removed, rectified,
  low-pass (10 Hz) with zero phase, negatives set to 0, channel minimum subtracted, divided
  by the channel maximum (over the whole recording);
* IK, ID, muscle-tendon lengths, velocities, moment arms and ground reactions:
  :func:`nmsm.tools.preprocess.trials.split_into_trials` (low-pass ``cutoff_frequency``
  except velocities and ground reactions, interpolating quintic spline to ``rows_per_trial``
  rows; centre-of-pressure NaN gaps stay gaps); EMG on the window widened by
  ``pad = ceil(emg_padding_time / dt)`` rows of ``dt = window / (rows - 1)`` each side, the
  spline's small undershoots below 0 set to 0.

Rotational IK columns are written in degrees (``inDegrees=yes``) as the input was.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.core.results import ResultsDirectory
from nmsm.errors import InputError
from nmsm.io.storage import Table
from nmsm.tools.pipeline.native import read_native_settings
from nmsm.tools.pipeline.preprocess_settings import TOOL, DataPreprocessingSettings, PreprocessTrial
from nmsm.tools.preprocess.run import EmgOptions, process_emg_table
from nmsm.tools.preprocess.tables import read_table
from nmsm.tools.preprocess.trials import TrialSources, split_into_trials


def read_settings(path: str | os.PathLike[str]) -> DataPreprocessingSettings:
    return read_native_settings(path, DataPreprocessingSettings, TOOL)


def process_emg(table: Table, high_pass: float, low_pass: float, order: int) -> np.ndarray:
    """Normalized EMG envelopes (n, channels) in [0, 1], per channel (module docstring)."""
    return process_emg_table(table, EmgOptions(order, high_pass, low_pass, demean="channel")).data


def _sources(settings: DataPreprocessingSettings, trial: PreprocessTrial) -> TrialSources:
    source = settings.motion_data_directory

    def found(folder: str) -> Path | None:
        path = source / folder / f"{trial.name}.sto"
        return path if path.is_file() else None

    emg = found("EMGData")
    if emg is not None:
        options = EmgOptions(settings.filter_order, settings.emg_high_pass_frequency, settings.emg_low_pass_frequency,
                             demean=settings.emg_demean)
        emg = process_emg_table(read_table(emg), options)
    ma = source / "MAData" / trial.name
    return TrialSources(ik=found("IKData"), inverse_dynamics=found("IDData"), grf=found("GRFData"), emg=emg,
                        muscle_analysis=ma if ma.is_dir() else None)


def run_settings(settings_file: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
                 **options: Any) -> Path:
    """Run the preprocessing stage of a ``<DataPreprocessingTool>`` settings file; returns
    the output data folder."""
    settings = read_settings(settings_file)
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    results = ResultsDirectory(settings.results_directory)
    for trial in settings.trials:
        if not (settings.motion_data_directory / "IKData" / f"{trial.name}.sto").is_file() and not (
                settings.motion_data_directory / "IDData" / f"{trial.name}.sto").is_file():
            raise InputError(f"no IKData or IDData file for trial '{trial.name}'", file=settings_file,
                             element=f"<Trial name=\"{trial.name}\">",
                             expected=f"{settings.motion_data_directory}/IKData/{trial.name}.sto")
        sources = _sources(settings, trial)
        pairs = trial.time_ranges
        for k in range(0, len(pairs), 2):
            name = f"{trial.name}_{k // 2 + 1}"
            with results.task(name) as stage:
                split_into_trials([(pairs[k], pairs[k + 1])], sources, stage, names=[name],
                                  rows=settings.rows_per_trial, cutoff=settings.cutoff_frequency,
                                  filter_order=settings.filter_order, emg_padding_time=settings.emg_padding_time,
                                  ik_radians=False, clip_emg=True)
    results.copy_in(settings_file, f"settings_{Path(settings_file).name}")
    return results.path

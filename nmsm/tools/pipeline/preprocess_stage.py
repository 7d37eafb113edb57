"""The preprocessing stage: full-length trials cut into the personalization tools' trials
(``<DataPreprocessingTool>``, docs/preprocess.md: ``processRawEmgFile`` and ``splitIntoTrials``),
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

Rotational IK columns are written in degrees (``inDegrees=yes``) as the input was; the IK
header is checked against the model's rotational coordinates (a wrong ``inDegrees`` warns).

Each full-length trial becomes one :class:`~nmsm.tools.preprocess.run.PreprocessRequest`
(its files read and its EMG processed once; each time window keeps its own EMG padding,
``emg_padding_per_window``), and all of them go through ``nmsm preprocess``'s checked path
(:func:`nmsm.tools.preprocess.command.run_checked`): every trial's files are read and
checked (each covers the trial's time ranges, the output folder holds no input, no earlier
run's files of the trials) before anything is processed, then the trials are written staged,
all or nothing. Errors name the settings file and element (or the data file at fault).
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
from nmsm.io.storage import Table
from nmsm.tools.pipeline.native import read_native_settings
from nmsm.tools.pipeline.preprocess_settings import TOOL, DataPreprocessingSettings, PreprocessTrial
from nmsm.tools.preprocess.command import run_checked
from nmsm.tools.preprocess.run import EmgOptions, PreprocessRequest, process_emg_table


def read_settings(path: str | os.PathLike[str]) -> DataPreprocessingSettings:
    return read_native_settings(path, DataPreprocessingSettings, TOOL)


def process_emg(table: Table, high_pass: float, low_pass: float, order: int) -> np.ndarray:
    """Normalized EMG envelopes (n, channels) in [0, 1], per channel (module docstring)."""
    return process_emg_table(table, EmgOptions(order, high_pass, low_pass, demean="channel")).data


def _elements(trial: PreprocessTrial) -> dict[str, str]:
    """``nmsm preprocess`` options -> the settings elements that give them for ``trial``."""
    at = f'<Trial name="{trial.name}">'
    return {"--output": "<results_directory>", "--time-pair": f"{at} <time_ranges>", "--prefix": at,
            "--rows": "<rows_per_trial>", "--cutoff": "<cutoff_frequency>", "--model": "<input_model_file>",
            "--emg-padding-time": "<emg_padding_time>", "--ik/--markers": f"{at} (IKData)",
            "--ik": f"{at} (IKData)", "--id": f"{at} (IDData)", "--raw-emg": f"{at} (EMGData)",
            "--grf": f"{at} (GRFData)", "--muscle-analysis": f"{at} (MAData)"}


def requests(settings: DataPreprocessingSettings, settings_file: Path) -> list[PreprocessRequest]:
    """One checked-path request per full-length trial, each time window with its own EMG
    padding (module docstring); :class:`InputError` for a trial with neither an IK nor an ID
    file."""
    source = settings.motion_data_directory
    out: list[PreprocessRequest] = []
    for trial in settings.trials:
        def found(folder: str) -> Path | None:
            path = source / folder / f"{trial.name}.sto"
            return path if path.is_file() else None

        if found("IKData") is None and found("IDData") is None:
            raise InputError(f"no IKData or IDData file for trial '{trial.name}'", file=settings_file,
                             element=f"<Trial name=\"{trial.name}\">",
                             expected=f"{source}/IKData/{trial.name}.sto")
        ma = source / "MAData" / trial.name
        pairs = tuple((trial.time_ranges[k], trial.time_ranges[k + 1]) for k in range(0, len(trial.time_ranges), 2))
        out.append(PreprocessRequest(
            time_pairs=pairs, output=settings.results_directory, model=settings.input_model_file, prefix=trial.name,
            rows=settings.rows_per_trial, cutoff=settings.cutoff_frequency, raw_emg=found("EMGData"),
            emg=EmgOptions(settings.filter_order, settings.emg_high_pass_frequency,
                           settings.emg_low_pass_frequency, demean=settings.emg_demean),
            emg_padding_time=settings.emg_padding_time, emg_padding_per_window=True, ik=found("IKData"),
            inverse_dynamics=found("IDData"), grf=found("GRFData"), muscle_analysis=ma if ma.is_dir() else None,
            filter_order=settings.filter_order, ik_radians=False, clip_emg=True, settings_file=settings_file,
            elements=_elements(trial)))
    return out


def run_settings(settings_file: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
                 **options: Any) -> Path:
    """Run the preprocessing stage of a ``<DataPreprocessingTool>`` settings file; returns
    the output data folder."""
    settings = read_settings(settings_file)
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    checked = requests(settings, Path(settings_file))
    windows = sum(len(r.time_pairs) for r in checked)
    announce("preprocess", settings=settings_file, model=settings.input_model_file,
             trials=[t.name for t in settings.trials],
             problem=f"{windows} time window(s) into {settings.rows_per_trial} rows each, low-pass "
                     f"{settings.cutoff_frequency:g} Hz")
    run_checked(checked, keep_intermediate=False)
    results = ResultsDirectory(settings.results_directory)
    results.copy_in(settings_file, f"settings_{Path(settings_file).name}")
    return results.path

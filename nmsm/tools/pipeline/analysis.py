"""The analysis stage: IK, ID and muscle analysis of recorded trials on the current model
(``<ModelAnalysisTool>``, :mod:`nmsm.tools.pipeline.analysis_settings`).

After Joint Model Personalization the model changed, so the pipeline re-runs, per trial:

1. inverse kinematics of the markers (:func:`nmsm.tools.jmp.ik.run_ik_files`) ->
   ``IKData/<trial>.sto`` (OpenSim motion, rotational coordinates in degrees) and
   ``IKErrors/<trial>.sto`` (marker distance errors, m);
2. inverse dynamics with the trial's ground reactions
   (:func:`nmsm.model.id_tool.inverse_dynamics_of_motion`) -> ``IDData/<trial>.sto``, or the
   trial's measured joint moments (``<inverse_dynamics_file>``, e.g. a dynamometer in a
   passive trial) checked against the IK frames (:func:`measured_moments`);
3. muscle analysis (:func:`nmsm.model.muscle_analysis.analyze_motion`; OpenSim through the
   bridge only for muscles with active wrapping) -> ``MAData/<trial>/...``;
4. copies of the ground reactions and raw EMG -> ``GRFData/<trial>.sto``,
   ``EMGData/<trial>.sto`` (what preprocessing splits into trials).

Everything is written through :class:`~nmsm.core.results.ResultsDirectory` (one task per
trial), with a copy of the settings file and ``analysis_report.txt`` (RMS marker errors).
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import attrs
import numpy as np

from nmsm.core.console import announce
from nmsm.core.results import ResultsDirectory
from nmsm.tools.pipeline.analysis_settings import TOOL, AnalysisTrial, ModelAnalysisSettings
from nmsm.tools.pipeline.native import read_native_settings

if TYPE_CHECKING:
    from nmsm.io.storage import Table

REPORT_FILE = "analysis_report.txt"


@attrs.frozen
class TrialAnalysis:
    """One analysed trial: RMS and largest marker error (m), frames, wall time (s)."""

    name: str
    frames: int
    rms_marker_error: float
    max_marker_error: float
    wall_time: float


@attrs.frozen
class AnalysisRun:
    settings: ModelAnalysisSettings
    results_directory: Path
    trials: tuple[TrialAnalysis, ...]


def read_settings(path: str | os.PathLike[str]) -> ModelAnalysisSettings:
    return read_native_settings(path, ModelAnalysisSettings, TOOL)


def measured_moments(path: Path, time: np.ndarray) -> Table:
    """The table of ``path`` (joint moments, N m) if it is sampled at the IK frames ``time``
    (s, within 1e-6 s), else an :class:`~nmsm.errors.InputError` naming the file."""
    from nmsm.errors import InputError
    from nmsm.io.storage import read_storage

    table = read_storage(path)
    inside = (table.time >= time[0] - 1e-6) & (table.time <= time[-1] + 1e-6)
    rows = table.time[inside]
    if rows.size != time.size or not np.allclose(rows, time, rtol=0.0, atol=1e-6):
        raise InputError(
            f"{rows.size} rows in {time[0]:g}-{time[-1]:g} s, the markers give {time.size} frames",
            file=path, expected="joint moments at the marker frames of the trial")
    return attrs.evolve(table, time=rows, data=table.data[inside])


def _analyse(settings: ModelAnalysisSettings, trial: AnalysisTrial, model: Any, stage: Path) -> TrialAnalysis:
    from nmsm.io.storage import read_storage, write_storage
    from nmsm.model.external_loads import read_external_loads
    from nmsm.model.id_tool import inverse_dynamics_of_motion
    from nmsm.model.muscle_analysis import analyze_motion
    from nmsm.tools.jmp.ik import marker_error_table, motion_table, run_ik_files

    began = time.perf_counter()
    for folder in ("IKData", "IKErrors", "IDData", "MAData", "GRFData", "EMGData"):
        (stage / folder).mkdir(parents=True, exist_ok=True)
    ik = run_ik_files(settings.input_model_file, trial.marker_file, ik_settings=trial.ik_settings_file,
                      time_range=trial.time_range, accuracy=settings.accuracy)
    motion = motion_table(ik)
    write_storage(stage / "IKData" / f"{trial.name}.sto", motion, name="Coordinates")
    write_storage(stage / "IKErrors" / f"{trial.name}.sto", marker_error_table(ik), name="MarkerErrors")
    loads = None
    if trial.external_loads_file is not None:
        loads = attrs.evolve(read_external_loads(trial.external_loads_file), data_file=trial.grf_file)
        shutil.copyfile(trial.grf_file, stage / "GRFData" / f"{trial.name}.sto")
    cutoff = settings.id_lowpass_cutoff_frequency
    if trial.inverse_dynamics_file is not None:
        moments = measured_moments(trial.inverse_dynamics_file, motion.time)
    else:
        moments = inverse_dynamics_of_motion(model, read_storage(stage / "IKData" / f"{trial.name}.sto"),
                                             external_loads=loads, lowpass_hz=cutoff if cutoff > 0 else None)
    write_storage(stage / "IDData" / f"{trial.name}.sto", moments, name="Inverse Dynamics")
    ma_cutoff = settings.muscle_analysis_lowpass_cutoff_frequency
    if model.muscles:
        geometry = analyze_motion(settings.input_model_file, motion, model=model,
                                  muscles=settings.muscle_list or None,
                                  coordinates=settings.muscle_analysis_coordinate_list or None,
                                  lowpass_hz=ma_cutoff if ma_cutoff > 0 else None)
        geometry.write(stage / "MAData", trial.name)
    if trial.emg_file is not None:
        shutil.copyfile(trial.emg_file, stage / "EMGData" / f"{trial.name}.sto")
    errors = ik.marker_errors[np.isfinite(ik.marker_errors)]
    return TrialAnalysis(trial.name, int(ik.time.size), float(np.sqrt(np.mean(errors**2))) if errors.size else 0.0,
                         float(errors.max(initial=0.0)), time.perf_counter() - began)


def run_settings(settings_file: str | os.PathLike[str], *, results_directory: str | os.PathLike[str] | None = None,
                 **options: Any) -> AnalysisRun:
    """Run the analysis stage of a ``<ModelAnalysisTool>`` settings file."""
    from nmsm.model.osim import load_model

    settings = read_settings(settings_file)
    if results_directory is not None:
        settings = attrs.evolve(settings, results_directory=Path(results_directory))
    inputs = [settings.input_model_file, *(path for t in settings.trials for path in
                                            (t.marker_file, t.inverse_dynamics_file, t.grf_file, t.emg_file)
                                            if path is not None)]
    results = ResultsDirectory(settings.results_directory, inputs=inputs)
    model = load_model(settings.input_model_file)
    measured = sum(t.inverse_dynamics_file is not None for t in settings.trials)
    steps = [f"IK of {len(model.coordinate_names)} coordinates",
             f"ID ({measured} trial(s) with measured moments)" if measured else "ID"]
    if model.muscles:
        steps.append(f"muscle analysis of {len(settings.muscle_list or model.muscles)} muscles")
    announce("analysis", settings=settings_file, model=settings.input_model_file,
             trials=[t.name for t in settings.trials], problem=", ".join(steps))
    done = []
    for trial in settings.trials:
        with results.task(trial.name) as stage:
            done.append(_analyse(settings, trial, model, stage))
    lines = [f"analysis of {len(done)} trial(s) on {settings.input_model_file}",
             f"{'trial':<16s} {'frames':>7s} {'RMS marker error (mm)':>22s} {'max (mm)':>9s} {'time (s)':>9s}"]
    lines += [f"{t.name:<16s} {t.frames:7d} {1000 * t.rms_marker_error:22.3f} {1000 * t.max_marker_error:9.3f} "
              f"{t.wall_time:9.1f}" for t in done]
    results.write_text(REPORT_FILE, "\n".join(lines) + "\n")
    results.copy_in(settings_file, Path(settings_file).name if Path(settings_file).parent.resolve()
                    != results.path.resolve() else f"settings_{Path(settings_file).name}")
    return AnalysisRun(settings, results.path, tuple(done))

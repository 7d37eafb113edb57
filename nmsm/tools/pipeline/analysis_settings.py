"""Settings of the analysis stage, ``<ModelAnalysisTool>``: inverse kinematics, inverse
dynamics and muscle analysis of recorded trials on the current model.

::

    <NMSMPipelineDocument Version="1.5.3"><ModelAnalysisTool>
      <results_directory>analysis</results_directory>
      <input_model_file>model_jmp.osim</input_model_file>
      <TrialSet>
        <Trial name="gait">
          <marker_file>gait.trc</marker_file>
          <ik_settings_file/>                          <!-- optional OpenSim IK setup: weights -->
          <grf_file>gait_grf.mot</grf_file>            <!-- optional: ID with these loads -->
          <external_loads_file>gait_grf.xml</external_loads_file>
          <emg_file>gait_emg.mot</emg_file>            <!-- optional: copied for preprocessing -->
          <time_range>0 1.4</time_range>               <!-- optional -->
        </Trial>
        <Trial name="passive_knee">
          <marker_file>passive_knee.trc</marker_file>
          <inverse_dynamics_file>passive_knee_moments.sto</inverse_dynamics_file>  <!-- measured moments -->
        </Trial>
      </TrialSet>
      <id_lowpass_cutoff_frequency>-1</id_lowpass_cutoff_frequency>
      <muscle_analysis_coordinate_list>hip_flexion_r knee_angle_r</muscle_analysis_coordinate_list>
    </ModelAnalysisTool></NMSMPipelineDocument>

Paths resolve relative to the settings file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import attrs

from nmsm.io.settings.schema import ReadContext, setting

TOOL = "ModelAnalysisTool"


def _window(value: tuple[float, ...] | None) -> str | None:
    if value is not None and not value[0] < value[1]:
        return f"start {value[0]} is not before end {value[1]}"
    return None


@attrs.frozen(kw_only=True)
class AnalysisTrial:
    """One recorded trial."""

    name: str = setting("name", kind="attribute", required=True, doc="Trial name (output file names)")
    marker_file: Path = setting("marker_file", kind="path", path_kind="file", required=True, example="trial.trc",
                                doc="Markers (.trc)")
    ik_settings_file: Path | None = setting("ik_settings_file", kind="path", path_kind="file", default=None,
                                            doc="OpenSim IK setup giving marker weights (optional)")
    grf_file: Path | None = setting("grf_file", kind="path", path_kind="file", default=None,
                                    doc="Ground reactions (.mot/.sto) for inverse dynamics (optional)")
    external_loads_file: Path | None = setting("external_loads_file", kind="path", path_kind="file", default=None,
                                               doc="ExternalLoads XML applying the grf_file columns to bodies")
    inverse_dynamics_file: Path | None = setting(
        "inverse_dynamics_file", kind="path", path_kind="file", default=None,
        doc="Joint moments measured otherwise (N m, columns <coordinate>_moment at the marker frames; e.g. a "
            "dynamometer in passive trials): written to IDData in place of inverse dynamics")
    emg_file: Path | None = setting("emg_file", kind="path", path_kind="file", default=None,
                                    doc="Raw EMG (.mot/.sto), copied to EMGData for preprocessing (optional)")
    time_range: tuple[float, ...] | None = setting("time_range", kind="numbers", count=2, default=None,
                                                   check=_window, doc="Start and end time (s); default all frames")

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if (values["grf_file"] is None) != (values["external_loads_file"] is None):
            raise ctx.error("grf_file", "grf_file and external_loads_file go together",
                            "both (inverse dynamics with ground reactions) or neither")
        if values["inverse_dynamics_file"] is not None and values["grf_file"] is not None:
            raise ctx.error("inverse_dynamics_file", "inverse_dynamics_file replaces inverse dynamics, so it "
                            "cannot go with grf_file", "either measured moments or ground reactions, not both")


@attrs.frozen(kw_only=True)
class ModelAnalysisSettings:
    """Validated ``<ModelAnalysisTool>`` settings."""

    settings_file: Path = setting(kind="settings_file", doc="the settings file", default=None)
    results_directory: Path = setting("results_directory", kind="path", output=True, empty_is_base=True, default=None,
                                      doc="Results folder: IKData, IDData, MAData, GRFData, EMGData")
    input_model_file: Path = setting("input_model_file", kind="path", path_kind="file", required=True,
                                     example="model.osim", doc="Model (.osim)")
    trials: tuple[AnalysisTrial, ...] = setting("Trial", kind="blocks", container="TrialSet", nested=AnalysisTrial,
                                                required=True, doc="Recorded trials")
    accuracy: float | None = setting("accuracy", kind="number", default=1e-6, doc="IK accuracy (OpenSim's meaning)")
    id_lowpass_cutoff_frequency: float = setting(
        "id_lowpass_cutoff_frequency", kind="number", default=-1.0,
        doc="Low-pass cutoff (Hz) of the coordinates before inverse dynamics; -1: none")
    muscle_analysis_coordinate_list: tuple[str, ...] = setting(
        "muscle_analysis_coordinate_list", kind="names", default=(),
        doc="Coordinates of the moment-arm files (default: every coordinate)")
    muscle_list: tuple[str, ...] = setting("muscle_list", kind="names", default=(),
                                           doc="Muscles analysed (default: every muscle)")
    muscle_analysis_lowpass_cutoff_frequency: float = setting(
        "muscle_analysis_lowpass_cutoff_frequency", kind="number", default=-1.0,
        doc="Low-pass cutoff (Hz) of the coordinates before muscle analysis; -1: none")

"""Settings of the preprocessing stage, ``<DataPreprocessingTool>``: full-length trials
(the analysis stage's ``IKData``, ``IDData``, ``MAData``, ``GRFData``, ``EMGData``) split into
the personalization tools' trials (docs/preprocess.md).

::

    <NMSMPipelineDocument Version="1.5.3"><DataPreprocessingTool>
      <results_directory>preprocessed</results_directory>
      <input_model_file>model_jmp.osim</input_model_file>
      <motion_data_directory>analysis</motion_data_directory>
      <TrialSet>
        <Trial name="gait"><time_ranges>0.2 1.0</time_ranges></Trial>   <!-- gait_1 -->
      </TrialSet>
      <rows_per_trial>101</rows_per_trial>
      <cutoff_frequency>6</cutoff_frequency>
      <emg_high_pass_frequency>40</emg_high_pass_frequency>
      <emg_low_pass_frequency>10</emg_low_pass_frequency>
      <emg_demean>channel</emg_demean>                 <!-- or frame: the original's -->
    </DataPreprocessingTool></NMSMPipelineDocument>
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import attrs

from nmsm.io.settings.schema import ReadContext, positive, setting

TOOL = "DataPreprocessingTool"


@attrs.frozen(kw_only=True)
class PreprocessTrial:
    """A full-length trial and the time windows (s) cut from it: ``<name>_1``, ``<name>_2``, ..."""

    name: str = setting("name", kind="attribute", required=True, doc="Trial name in the motion data folder")
    time_ranges: tuple[float, ...] = setting("time_ranges", kind="numbers", required=True, example="0.5 1.6",
                                             doc="Start end pairs (s), one trial each")

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        pairs = values["time_ranges"]
        if len(pairs) % 2 or not all(pairs[k] < pairs[k + 1] for k in range(0, len(pairs), 2)):
            raise ctx.error("time_ranges", f"{pairs} are not start-end pairs", "pairs 'start end' with start < end")


@attrs.frozen(kw_only=True)
class DataPreprocessingSettings:
    """Validated ``<DataPreprocessingTool>`` settings."""

    settings_file: Path = setting(kind="settings_file", doc="the settings file", default=None)
    results_directory: Path = setting("results_directory", kind="path", output=True, empty_is_base=True, default=None,
                                      doc="Output data folder (IKData, IDData, EMGData, GRFData, MAData)")
    input_model_file: Path = setting("input_model_file", kind="path", path_kind="file", required=True,
                                     example="model.osim", doc="Model (degrees of rotational coordinates)")
    motion_data_directory: Path = setting("motion_data_directory", kind="path", path_kind="dir", required=True,
                                          example="analysis", doc="Full-length trials (analysis stage output)")
    trials: tuple[PreprocessTrial, ...] = setting("Trial", kind="blocks", container="TrialSet",
                                                  nested=PreprocessTrial, required=True, doc="Trials to cut")
    rows_per_trial: int = setting("rows_per_trial", kind="integer", default=101, check=positive,
                                  doc="Rows of each output trial")
    cutoff_frequency: float = setting("cutoff_frequency", kind="number", default=6.0, check=positive,
                                      doc="Low-pass cutoff (Hz) of IK, ID, lengths and moment arms")
    filter_order: int = setting("filter_order", kind="integer", default=4, check=positive,
                                doc="Butterworth order of every filter")
    emg_high_pass_frequency: float = setting("emg_high_pass_frequency", kind="number", default=40.0, check=positive,
                                             doc="EMG high-pass cutoff (Hz)")
    emg_low_pass_frequency: float = setting("emg_low_pass_frequency", kind="number", default=10.0, check=positive,
                                            doc="EMG envelope low-pass cutoff (Hz)")
    emg_demean: str = setting("emg_demean", kind="text", default="channel", choices=("channel", "frame"),
                              doc="EMG mean and minimum per channel over time (channel), or across channels "
                                  "at each frame as the original computes them (frame)")
    emg_padding_time: float = setting("emg_padding_time", kind="number", default=0.2, check=positive,
                                      doc="EMG kept before and after each trial (s), for the electromechanical delay")

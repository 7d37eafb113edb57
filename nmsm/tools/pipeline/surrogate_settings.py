"""Settings of the surrogate-data stage, ``<SurrogateDataTool>``: poses sampled around a
reference motion and their muscle analyses, the data a synergy-driven treatment fits its
polynomial muscle surrogate to (docs/model.md, the original's ``sampleSurrogateKinematics``).

::

    <NMSMPipelineDocument Version="1.5.3"><SurrogateDataTool>
      <results_directory>surrogateData</results_directory>
      <input_model_file>model.osim</input_model_file>
      <data_directory>preprocessed</data_directory>            <!-- IKData/<trial_name>.sto -->
      <trial_name>gait_1</trial_name>
      <coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>
      <samples_per_frame>25</samples_per_frame>
      <angular_padding>10</angular_padding>                    <!-- degrees -->
      <frame_stride>2</frame_stride>
    </SurrogateDataTool></NMSMPipelineDocument>
"""

from __future__ import annotations

from pathlib import Path

import attrs

from nmsm.io.settings.schema import at_least_one, non_negative, not_empty, setting

TOOL = "SurrogateDataTool"


@attrs.frozen(kw_only=True)
class SurrogateDataSettings:
    """Validated ``<SurrogateDataTool>`` settings."""

    settings_file: Path = setting(kind="settings_file", doc="the settings file", default=None)
    results_directory: Path = setting("results_directory", kind="path", output=True, empty_is_base=True, default=None,
                                      doc="Output folder: IKData/<trial>.sto and MAData/<trial>/")
    input_model_file: Path = setting("input_model_file", kind="path", path_kind="file", required=True,
                                     example="model.osim", doc="Model (.osim)")
    data_directory: Path = setting("data_directory", kind="path", path_kind="dir", required=True,
                                   example="preprocessed", doc="Folder with IKData/<trial_name>.sto (the reference)")
    trial_name: str = setting("trial_name", kind="text", required=True, example="trial", doc="Reference trial")
    coordinate_list: tuple[str, ...] = setting("coordinate_list", kind="names", required=True, check=not_empty,
                                               example="knee_angle_r", doc="Coordinates sampled (the others follow "
                                               "the reference)")
    samples_per_frame: int = setting("samples_per_frame", kind="integer", default=25, check=at_least_one,
                                     doc="Latin-hypercube samples per reference frame")
    angular_padding: float = setting("angular_padding", kind="number", default=10.0, check=non_negative,
                                     doc="Sampled range around the reference, rotational coordinates (degrees)")
    linear_padding: float = setting("linear_padding", kind="number", default=0.01, check=non_negative,
                                    doc="Sampled range around the reference, translational coordinates (m)")
    frame_stride: int = setting("frame_stride", kind="integer", default=1, check=at_least_one,
                                doc="Use every n-th reference frame")
    seed: int = setting("seed", kind="integer", default=0, doc="Random seed of the sampling")

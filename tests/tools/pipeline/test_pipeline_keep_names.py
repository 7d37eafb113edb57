"""``<keep_settings_inputs>`` names an element the runner rewires (fuzz audit of pipeline files).

A misspelled name (``input_model_fle``) kept nothing: ``nmsm pipeline --check`` accepted it and
the runner rewired the element anyway, e.g. ran MTP on JMP's model when the stage was meant to
run on its own reduced model. Now one error at the element's line naming the stage, the name,
close matches and the names that stage's kind accepts."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.tools.pipeline.pipeline_file import read_pipeline


def _pipeline(folder: Path, tool: str, keep: str) -> Path:
    path = folder / "pipeline.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.3"><PipelineTool name="p">
  <results_directory>results</results_directory>
  <StageList>
    <Stage name="s">
      <keep_settings_inputs>{keep}</keep_settings_inputs>
      <{tool}/>
    </Stage>
  </StageList>
</PipelineTool></NMSMPipelineDocument>
""")
    return path


@pytest.mark.parametrize(("tool", "keep", "hint"), [
    ("MuscleTendonPersonalizationTool", "input_model_fle", "did you mean 'input_model_file'"),
    ("GroundContactPersonalizationTool", "input_model_file data_directory", "did you mean 'input_directory'"),
    ("JointModelPersonalizationTool", "input_osimx_file", ""),
])
def test_a_name_the_runner_does_not_rewire_is_one_error_at_its_line(tmp_path, tool, keep, hint) -> None:
    path = _pipeline(tmp_path, tool, keep)
    with pytest.raises(InputError) as info:
        read_pipeline(path)
    error = info.value
    assert error.line == 5 and error.element == "<keep_settings_inputs>" and error.file == str(path)
    assert "stage 's'" in str(error) and hint in str(error) and "input_model_file" in str(error)


@pytest.mark.parametrize(("tool", "keep"), [
    ("MuscleTendonPersonalizationTool", "input_model_file input_osimx_file data_directory"),
    ("GroundContactPersonalizationTool", "input_model_file input_osimx_file input_directory"),
    ("TrackingOptimizationTool", "initial_guess_directory tracked_quantities_directory"),
    ("TrackingOptimizationTool", "RCNLSynergyController/surrogate_model_data_directory"),
    ("VerificationOptimizationTool", "surrogate_model_data_directory"),
    ("NeuralControlPersonalizationTool", ""),
])
def test_the_rewired_elements_may_be_kept(tmp_path, tool, keep) -> None:
    assert read_pipeline(_pipeline(tmp_path, tool, keep)).stages[0].keep == tuple(keep.split())

"""The results tree's folders named by a pipeline file (fuzz audit of pipeline files): a
``<results_directory>`` that is an existing file, and a stage name longer than a folder name
may be, were accepted by ``--check`` and a ``FileExistsError`` / ``OSError: File name too
long`` traceback when the pipeline ran. Now each is one error at its line."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.tools.pipeline.pipeline_file import MAX_NAME, read_pipeline


def _pipeline(folder: Path, results: str = "results", name: str = "mtp") -> Path:
    path = folder / "pipeline.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.3"><PipelineTool name="p">
  <results_directory>{results}</results_directory>
  <StageList>
    <Stage name="{name}"><MuscleTendonPersonalizationTool/></Stage>
  </StageList>
</PipelineTool></NMSMPipelineDocument>
""")
    return path


def test_a_results_directory_that_is_a_file_is_one_error(tmp_path: Path) -> None:
    (tmp_path / "results.txt").write_text("not a folder\n")
    path = _pipeline(tmp_path, results="results.txt")
    with pytest.raises(InputError, match="'results.txt' is a file") as info:
        read_pipeline(path)
    assert info.value.line == 2 and info.value.element == "<results_directory>"
    (tmp_path / "results").mkdir()
    assert read_pipeline(_pipeline(tmp_path)).results_directory == tmp_path / "results"


def test_a_stage_name_too_long_for_a_folder_is_one_error(tmp_path: Path) -> None:
    path = _pipeline(tmp_path, name="x" * (MAX_NAME + 1))
    with pytest.raises(InputError, match=f"at most {MAX_NAME} characters") as info:
        read_pipeline(path)
    assert info.value.line == 4 and info.value.element == "<Stage name>"
    name = "x" * MAX_NAME
    assert read_pipeline(_pipeline(tmp_path, name=name)).stages[0].name == name
    aside = tmp_path / f".{name}.earlier"  # the longest folder the runner makes of it
    aside.mkdir()
    assert aside.is_dir()

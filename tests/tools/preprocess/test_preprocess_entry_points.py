"""Every way of starting preprocessing takes ``nmsm preprocess``'s checked path: the Python
function :func:`nmsm.tools.preprocess.command.preprocess`, the ``<DataPreprocessingTool>``
settings file (``nmsm run``) and the pipeline's preprocessing stage give the same checked
error for the same bad input and leave no file behind."""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.storage import table_from_columns, write_storage
from nmsm.tools.preprocess.command import preprocess
from nmsm.tools.preprocess.run import EmgOptions, PreprocessRequest
from nmsm.tools.preprocess.velocity import create_velocity_file

SHORT_ID = "ID covers 0-1.7 s but the trial needs 1.8-2.6 s"


def _write(path: Path, time: np.ndarray, columns: dict[str, np.ndarray], in_degrees: bool = False) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_storage(path, table_from_columns(time, columns, in_degrees=in_degrees))
    return path


def _snapshot(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture
def analysis(tmp_path: Path) -> Path:
    """Full-length trial 'gait' (0-3 s) as the analysis stage writes it, and the model."""
    from nmsm.examples.synthetic_jmp import leg_model_xml

    t = np.linspace(0.0, 3.0, 301)
    data = tmp_path / "analysis"
    _write(data / "IKData" / "gait.sto", t, {"knee_angle_r": 20 + 10 * np.sin(2 * t)}, in_degrees=True)
    _write(data / "IDData" / "gait.sto", t, {"knee_angle_r_moment": 10 * np.sin(t)})
    te = np.arange(0.0, 3.0, 1e-3)
    rng = np.random.default_rng(4)
    _write(data / "EMGData" / "gait.sto", te, {name: (1 + np.sin(k + 3 * te)) * rng.standard_normal(te.size)
                                                for k, name in enumerate(("Sol", "TibAnt"))})
    ma = data / "MAData" / "gait"
    _write(ma / "gait_Length.sto", t, {"soleus_r": 0.3 + 0.01 * np.sin(2 * t)})
    _write(ma / "gait_MomentArm_knee_angle_r.sto", t, {"soleus_r": 0.04 + 0 * t})
    create_velocity_file(ma / "gait_Length.sto")
    (tmp_path / "model.osim").write_text(leg_model_xml().decode().replace('"knee_angle"', '"knee_angle_r"'))
    return data


def _shorten_id(data: Path) -> Path:
    """The trial's files disagree: its ID ends at 1.7 s (within the first window, before the
    second), its IK at 3 s."""
    t = np.linspace(0.0, 1.7, 171)
    return _write(data / "IDData" / "gait.sto", t, {"knee_angle_r_moment": 10 * np.sin(t)})


def _request(data: Path, output: Path) -> PreprocessRequest:
    return PreprocessRequest(time_pairs=((0.5, 1.6), (1.8, 2.6)), output=output, model=data.parent / "model.osim",
                             prefix="gait", ik=data / "IKData" / "gait.sto", inverse_dynamics=data / "IDData" / "gait.sto",
                             raw_emg=data / "EMGData" / "gait.sto", emg=EmgOptions(demean="channel"),
                             muscle_analysis=data / "MAData" / "gait")


def _stage_settings(folder: Path, results: str = "out") -> Path:
    settings = folder / "pre.xml"
    settings.write_text('<NMSMPipelineDocument Version="1.5.3"><DataPreprocessingTool>'
                        f"<results_directory>{results}</results_directory>"
                        "<input_model_file>model.osim</input_model_file>"
                        "<motion_data_directory>analysis</motion_data_directory><TrialSet><Trial name='gait'>"
                        "<time_ranges>0.5 1.6 1.8 2.6</time_ranges></Trial></TrialSet></DataPreprocessingTool>"
                        "</NMSMPipelineDocument>")
    return settings


def test_python_function_checks_first_and_stages(analysis: Path, tmp_path: Path) -> None:
    """``command.preprocess``: the trial's disagreeing files and an output folder among the inputs
    are refused before anything is written; good input is written as before."""
    id_file = _shorten_id(analysis)
    out = tmp_path / "out"
    with pytest.raises(InputError) as info:
        preprocess(_request(analysis, out))
    assert str(info.value).startswith(f"{id_file}: {SHORT_ID}")
    assert not out.exists()
    before = _snapshot(analysis)
    with pytest.raises(InputError, match=r"--output: the output folder .*IKData holds the input .*gait.sto \(--ik\)"):
        preprocess(_request(analysis, analysis / "IKData"))
    assert _snapshot(analysis) == before
    _write(id_file, np.linspace(0.0, 3.0, 301), {"knee_angle_r_moment": np.zeros(301)})
    assert preprocess(_request(analysis, out)) == ["gait_1", "gait_2"]
    assert (out / "MAData" / "gait_2" / "gait_2_Velocity.sto").is_file()
    assert not [p for p in out.iterdir() if p.name.startswith(".")]  # no staging folder left


def test_settings_file_stage_checks_first_and_stages(analysis: Path, tmp_path: Path,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    """``nmsm run`` on a ``<DataPreprocessingTool>`` file: the same checked errors, the
    settings file and element named where no data file is at fault; no file written (the
    first window's trial included)."""
    id_file = _shorten_id(analysis)
    settings = _stage_settings(tmp_path)
    assert main(["run", str(settings)]) == 1
    assert capsys.readouterr().err.startswith(f"nmsm: error: {id_file}: {SHORT_ID}")
    assert not (tmp_path / "out").exists()
    before = _snapshot(analysis)
    inside = _stage_settings(tmp_path, "analysis/IKData")
    assert main(["run", str(inside)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"nmsm: error: {inside}: <results_directory>: the output folder "), err
    assert 'holds the input' in err and '(<Trial name="gait"> (IKData))' in err, err  # not the option --ik
    assert _snapshot(analysis) == before


def test_pipeline_stage_checks_first(analysis: Path, tmp_path: Path) -> None:
    """The pipeline's preprocessing stage: the same checked error, nothing left in its folder;
    an IK whose ``inDegrees`` header is wrong warns as ``nmsm preprocess`` does (the model's
    rotational coordinates are checked)."""
    from nmsm.tools.pipeline.runner import run_pipeline_file

    id_file = _shorten_id(analysis)
    _stage_settings(tmp_path)
    pipeline = tmp_path / "pipeline.xml"
    pipeline.write_text('<NMSMPipelineDocument Version="1.5.3"><PipelineTool name="p">'
                        "<results_directory>results</results_directory><input_model_file>model.osim</input_model_file>"
                        "<motion_data_directory>analysis</motion_data_directory><StageList>"
                        '<Stage name="pre"><settings_file>pre.xml</settings_file></Stage>'
                        "</StageList></PipelineTool></NMSMPipelineDocument>")
    with pytest.raises(InputError) as info:
        run_pipeline_file(pipeline, log=None)
    assert str(info.value).startswith(f"{id_file}: {SHORT_ID}")
    assert not (tmp_path / "results" / "pre").exists()
    _write(id_file, np.linspace(0.0, 3.0, 301), {"knee_angle_r_moment": np.zeros(301)})
    ik = analysis / "IKData" / "gait.sto"
    ik.write_text(ik.read_text().replace("inDegrees=yes", "inDegrees=no"))
    with pytest.warns(UserWarning, match=rf"{ik}: read with inDegrees=no, rotational column\(s\) 'knee_angle_r'"):
        run_pipeline_file(pipeline, log=None)
    assert sorted(p.name for p in (tmp_path / "results" / "pre" / "IKData").iterdir()) == ["gait_1.sto", "gait_2.sto"]


def test_settings_file_names_its_element_for_earlier_trial_files(analysis: Path, tmp_path: Path,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    """A second ``nmsm run`` of the settings without the EMG would leave the first run's EMG
    of the same trials: refused at the settings file's ``<results_directory>`` (was the
    option ``--output``), the folder named in the message."""
    settings = _stage_settings(tmp_path)
    assert main(["run", str(settings)]) == 0
    (analysis / "EMGData" / "gait.sto").unlink()
    capsys.readouterr()
    assert main(["run", str(settings)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"nmsm: error: {settings}: <results_directory>: the output folder {tmp_path / 'out'} "
                          "already holds files of trial(s) gait_1, gait_2 that this run would not rewrite: "
                          "EMGData/gait_1.sto"), err

"""The pipeline's own stages (analysis, preprocessing, surrogate data): settings errors, the
EMG envelope, resampling with centre-of-pressure gaps, ``nmsm run`` dispatch."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import Table
from nmsm.tools.dispatch import tool_element_name
from nmsm.tools.pipeline.analysis import measured_moments
from nmsm.tools.pipeline.analysis import read_settings as read_analysis
from nmsm.tools.pipeline.preprocess_stage import process_emg
from nmsm.tools.pipeline.preprocess_stage import read_settings as read_preprocess
from nmsm.tools.pipeline.preprocess_stage import run_settings as run_preprocess
from nmsm.tools.preprocess.signals import resample_with_gaps


def _write(path: Path, tool: str) -> Path:
    path.write_text(f'<NMSMPipelineDocument Version="1.5.3">{tool}</NMSMPipelineDocument>')
    return path


def test_analysis_settings_need_loads_with_ground_reactions(tmp_path: Path) -> None:
    for name in ("model.osim", "trial.trc", "grf.mot"):
        (tmp_path / name).write_text("x")
    path = _write(tmp_path / "a.xml", "<ModelAnalysisTool><input_model_file>model.osim</input_model_file>"
                  "<TrialSet><Trial name='t'><marker_file>trial.trc</marker_file><grf_file>grf.mot</grf_file>"
                  "</Trial></TrialSet></ModelAnalysisTool>")
    with pytest.raises(InputError, match="grf_file and external_loads_file go together"):
        read_analysis(path)
    missing = _write(tmp_path / "b.xml", "<ModelAnalysisTool><input_model_file>model.osim</input_model_file>"
                     "<TrialSet><Trial name='t'><marker_file>nope.trc</marker_file></Trial></TrialSet>"
                     "</ModelAnalysisTool>")
    with pytest.raises(InputError, match="nope.trc"):
        read_analysis(missing)
    assert tool_element_name(missing) == "ModelAnalysisTool"


def test_measured_moments_replace_inverse_dynamics(tmp_path: Path) -> None:
    """A passive trial's measured moments: refused next to ground reactions; taken at the
    marker frames; a file sampled elsewhere is named in the error."""
    from nmsm.io.storage import write_storage

    for name in ("model.osim", "trial.trc", "grf.mot", "loads.xml"):
        (tmp_path / name).write_text("x")
    moments_file = tmp_path / "moments.sto"
    time = np.round(np.arange(0.0, 1.0 + 1e-9, 0.01), 9)
    write_storage(moments_file, Table(time=time, labels=("knee_angle_r_moment",), data=np.sin(time)))
    both = _write(tmp_path / "a.xml", "<ModelAnalysisTool><input_model_file>model.osim</input_model_file>"
                  "<TrialSet><Trial name='t'><marker_file>trial.trc</marker_file><grf_file>grf.mot</grf_file>"
                  "<external_loads_file>loads.xml</external_loads_file>"
                  "<inverse_dynamics_file>moments.sto</inverse_dynamics_file></Trial></TrialSet></ModelAnalysisTool>")
    with pytest.raises(InputError, match="cannot go with grf_file"):
        read_analysis(both)
    frames = time[20:51]
    taken = measured_moments(moments_file, frames)
    np.testing.assert_allclose(taken.time, frames)
    np.testing.assert_allclose(taken.column("knee_angle_r_moment"), np.sin(frames))
    with pytest.raises(InputError, match="moments.sto") as error:
        measured_moments(moments_file, np.linspace(0.2, 0.5, 7))
    assert "markers give 7 frames" in str(error.value)


def test_preprocess_settings_and_missing_trial(tmp_path: Path) -> None:
    (tmp_path / "model.osim").write_text("x")
    (tmp_path / "analysis" / "IKData").mkdir(parents=True)
    odd = _write(tmp_path / "odd.xml", "<DataPreprocessingTool><input_model_file>model.osim</input_model_file>"
                 "<motion_data_directory>analysis</motion_data_directory><TrialSet><Trial name='gait'>"
                 "<time_ranges>0.5 0.2</time_ranges></Trial></TrialSet></DataPreprocessingTool>")
    with pytest.raises(InputError, match="not start-end pairs"):
        read_preprocess(odd)
    path = _write(tmp_path / "p.xml", "<DataPreprocessingTool><results_directory>out</results_directory>"
                  "<input_model_file>model.osim</input_model_file><motion_data_directory>analysis"
                  "</motion_data_directory><TrialSet><Trial name='gait'><time_ranges>0.2 0.5</time_ranges></Trial>"
                  "</TrialSet></DataPreprocessingTool>")
    with pytest.raises(InputError, match="no IKData or IDData file for trial 'gait'"):
        run_preprocess(path)


def test_emg_envelope_recovers_a_modulated_excitation() -> None:
    rate = 1000.0
    time = np.arange(0, 2.0, 1 / rate)
    envelope = 0.2 + 0.6 * np.exp(-0.5 * ((time - 1.0) / 0.15) ** 2)
    raw = np.column_stack([0.7 * envelope * np.sin(2 * np.pi * 130 * time)])
    processed = process_emg(Table(time=time, labels=("A",), data=raw), 40.0, 10.0, 4)[:, 0]
    inner = (time > 0.3) & (time < 1.7)
    expected = (envelope - envelope[inner].min()) / (envelope[inner].max() - envelope[inner].min())
    # normalized shape within 3 % of the envelope's range away from the filters' edges
    scale = processed[inner].max() - processed[inner].min()
    shape = (processed[inner] - processed[inner].min()) / scale
    assert np.max(np.abs(shape - expected[inner])) < 0.03
    assert processed.max() == pytest.approx(1.0) and processed.min() >= 0.0


def test_center_of_pressure_gaps_resample_without_mixing() -> None:
    time = np.linspace(0, 1, 11)
    point = np.where(time < 0.45, np.nan, 0.3 + 0.1 * time)
    out = resample_with_gaps(time, point[:, None], np.array([0.1, 0.42, 0.47, 0.55, 0.95]))[:, 0]
    assert np.isnan(out[0])  # between two gap samples
    assert out[1] == pytest.approx(0.35) and out[2] == pytest.approx(0.35)  # gap edge: the valid neighbour
    assert out[3] == pytest.approx(0.3 + 0.1 * 0.55)
    assert out[4] == pytest.approx(0.3 + 0.1 * 0.95)

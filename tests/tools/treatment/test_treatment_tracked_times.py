"""Tracked ID/GRF files on other times than the tracked IK, and IK times in milliseconds, are
InputErrors naming the file (both ran: each file is read from its own start, so an ID file
0.05 s late was tracked shifted by 0.05 s, with only an initial-guess warning; milliseconds
made every velocity 1000 times too slow)."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.treatment.run import run_settings
from test_treatment_input_checks import SOLVER  # the same coarse IPOPT settings

SETTINGS = """<NMSMPipelineDocument Version="1.5.0"><TrackingOptimizationTool>
 <results_directory>{tmp}/results</results_directory>
 <initial_guess_directory>{data}</initial_guess_directory>
 <tracked_quantities_directory>{data}</tracked_quantities_directory>
 <input_model_file>{model}</input_model_file><input_osimx_file/>
 <optimal_control_solver_settings_file>{tmp}/solver.xml</optimal_control_solver_settings_file>
 <trial_name>arm1</trial_name><states_coordinate_list>r_elbow_flex</states_coordinate_list>
 <RCNLTorqueController><coordinate_list>r_elbow_flex</coordinate_list></RCNLTorqueController>
 <RCNLCostTermSet>
  <RCNLCostTerm><type>generalized_coordinate_tracking</type><is_enabled>true</is_enabled>
   <coordinate_list>r_elbow_flex</coordinate_list><max_allowable_error>0.1</max_allowable_error></RCNLCostTerm>
  <RCNLCostTerm><type>inverse_dynamics_load_tracking</type><is_enabled>true</is_enabled>
   <load_list>r_elbow_flex_moment</load_list><max_allowable_error>20</max_allowable_error></RCNLCostTerm>
 </RCNLCostTermSet>
 <RCNLConstraintTermSet/>
</TrackingOptimizationTool></NMSMPipelineDocument>
"""


def _case(shared_data: Path, tmp_path: Path) -> tuple[Path, Path]:
    source = shared_data / "treatment" / "toy_arm" / "tracking_optimization"
    data = tmp_path / "preprocessed"
    shutil.copytree(source / "preprocessed", data)
    (tmp_path / "solver.xml").write_text(SOLVER)
    settings = tmp_path / "settings.xml"
    settings.write_text(SETTINGS.format(tmp=tmp_path, data=data, model=source / "simple_arm.osim"))
    return settings, data


def _retime(path: Path, change) -> None:
    table = read_storage(path)
    write_storage(path, table_from_columns(change(table.time), {k: table.column(k) for k in table.labels},
                                           in_degrees=table.in_degrees, name=table.name))


def _error(settings: Path) -> str:
    with pytest.raises(InputError) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(settings, evaluate_only=True)
    return str(info.value)


@pytest.mark.shared_data
def test_tracked_id_starting_later_is_an_error(shared_data: Path, tmp_path: Path) -> None:
    settings, data = _case(shared_data, tmp_path)
    _retime(data / "IDData" / "arm1.sto", lambda t: t + 0.05)
    message = _error(settings)
    assert str(data / "IDData" / "arm1.sto") in message and "column 'time'" in message
    assert "the tracked IDData file covers 0.05-" in message and "but the tracked IK" in message


@pytest.mark.shared_data
def test_tracked_id_of_a_shorter_window_is_an_error(shared_data: Path, tmp_path: Path) -> None:
    settings, data = _case(shared_data, tmp_path)
    path = data / "IDData" / "arm1.sto"
    table = read_storage(path)
    write_storage(path, table_from_columns(table.time[:-10], {k: table.column(k)[:-10] for k in table.labels}))
    assert "the tracked IDData file covers" in _error(settings)


@pytest.mark.shared_data
def test_times_in_milliseconds_are_an_error(shared_data: Path, tmp_path: Path) -> None:
    settings, data = _case(shared_data, tmp_path)
    for sub in ("IKData", "IDData"):
        _retime(data / sub / "arm1.sto", lambda t: t * 1000.0)
    message = _error(settings)
    assert str(data / "IKData" / "arm1.sto") in message and "are the times in milliseconds?" in message


@pytest.mark.shared_data
def test_every_file_offset_alike_runs_as_without(shared_data: Path, tmp_path: Path) -> None:
    costs = []
    for name, offset in (("plain", 0.0), ("offset", 10.0)):
        folder = tmp_path / name
        folder.mkdir()
        settings, data = _case(shared_data, folder)
        for sub in ("IKData", "IDData"):
            _retime(data / sub / "arm1.sto", lambda t: t + offset)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            outcome = run_settings(settings, evaluate_only=True)
        costs.append(outcome.solution.term_costs)
    assert costs[0].keys() == costs[1].keys()
    for name, value in costs[0].items():
        np.testing.assert_allclose(np.asarray(costs[1][name], dtype=float), np.asarray(value, dtype=float), rtol=1e-9, atol=1e-12)


@pytest.mark.shared_data
def test_a_longer_tracked_id_file_is_read_over_the_motion(shared_data: Path, tmp_path: Path) -> None:
    """An ID file starting with the IK and lasting longer is fine: only its first part is used
    (the same costs as the file cut to the IK's times, to the 0.4 % by which the spline through
    the later samples differs near the end from the cut file's end condition)."""
    costs = []
    for name, extra in (("plain", 0), ("longer", 20)):
        folder = tmp_path / name
        folder.mkdir()
        settings, data = _case(shared_data, folder)
        path = data / "IDData" / "arm1.sto"
        table = read_storage(path)
        if extra:
            step = float(np.median(np.diff(table.time)))
            time = np.concatenate([table.time, table.time[-1] + step * np.arange(1, extra + 1)])
            def continued(v: np.ndarray) -> np.ndarray:  # the recording going on: the last slope continued
                return np.concatenate([v, v[-1] + (v[-1] - v[-2]) * np.arange(1, extra + 1)])

            write_storage(path, table_from_columns(time, {k: continued(table.column(k)) for k in table.labels}))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            costs.append(run_settings(settings, evaluate_only=True).solution.term_costs)
    for term, value in costs[0].items():
        np.testing.assert_allclose(np.asarray(costs[1][term], dtype=float), np.asarray(value, dtype=float),
                                   rtol=1e-2, atol=1e-12)


@pytest.mark.shared_data
def test_a_short_motion_on_a_coarse_grid_is_not_taken_for_milliseconds(shared_data: Path, tmp_path: Path) -> None:
    """Frames 0.6 s apart over a few seconds (a coarse collocation mesh of earlier results) are
    seconds; only a long motion with sparse frames is taken for milliseconds."""
    from nmsm.tools.treatment.inputs import _check_tracked_times

    ik = table_from_columns(np.arange(0.0, 6.0, 0.6), {"q": np.zeros(10)})
    _check_tracked_times(ik, (), {})
    with pytest.raises(InputError, match="milliseconds"):
        _check_tracked_times(table_from_columns(np.arange(0.0, 300.0, 5.0), {"q": np.zeros(60)}), (), {})

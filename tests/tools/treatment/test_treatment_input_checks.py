"""Input checks of TO/VO/DO found by the treatment audit: terms' messages, defaults, guess times.

Audit cases: c04 (no ``<max_allowable_error>``), c05 (missing ``<coordinate>``), c06/c07/c12
(range errors of a term element), c11 (``<coordinate>`` named as written), c16 (missing ID
column), c19 (initial guess on other times), P12 (upgrade warnings printed twice). Every case
runs the toy arm (current schema, ``evaluate_only``: a second each), free-final-time Design
Optimization included.
"""

from __future__ import annotations

import collections
import re
import warnings
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.treatment.run import run_settings

TOY = """<NMSMPipelineDocument Version="1.5.0"><{tool}>
 <results_directory>{tmp}/results</results_directory>
 <initial_guess_directory>{data}/preprocessed</initial_guess_directory>
 <tracked_quantities_directory>{data}/preprocessed</tracked_quantities_directory>
 <input_model_file>{data}/simple_arm.osim</input_model_file><input_osimx_file/>
 <optimal_control_solver_settings_file>{tmp}/solver.xml</optimal_control_solver_settings_file>
 <trial_name>arm1</trial_name><states_coordinate_list>r_elbow_flex</states_coordinate_list>
 <RCNLTorqueController><coordinate_list>r_elbow_flex</coordinate_list></RCNLTorqueController>{extra}
 <RCNLCostTermSet>
  <RCNLCostTerm>
   <type>generalized_coordinate_tracking</type>
   <is_enabled>true</is_enabled>
   <coordinate_list>r_elbow_flex</coordinate_list>
   <max_allowable_error>0.1</max_allowable_error>
  </RCNLCostTerm>
  <RCNLCostTerm>
   <type>inverse_dynamics_load_tracking</type>
   <is_enabled>true</is_enabled>
   <load_list>r_elbow_flex_moment</load_list>
   <max_allowable_error>20</max_allowable_error>
  </RCNLCostTerm>
 </RCNLCostTermSet>
 <RCNLConstraintTermSet>
  <RCNLConstraintTerm>
   <type>kinetic_consistency</type>
   <is_enabled>true</is_enabled>
   <load_list>r_elbow_flex_moment</load_list>
   <max_error>0.1</max_error>
   <min_error>-0.1</min_error>
  </RCNLConstraintTerm>
 </RCNLConstraintTermSet>
</{tool}></NMSMPipelineDocument>
"""
SOLVER = """<NMSMPipelineDocument Version="1.5.0"><OptimalControlSolverSettings><GpopsSettings>
 <setup_mesh_method>none</setup_mesh_method><setup_mesh_phase_intervals>5</setup_mesh_phase_intervals>
 <setup_mesh_phase_colpoints_per_Interval>10</setup_mesh_phase_colpoints_per_Interval>
 <setup_nlp_solver>ipopt</setup_nlp_solver><setup_nlp_linear_solver>mumps</setup_nlp_linear_solver>
 <setup_nlp_tolerance>1e-3</setup_nlp_tolerance>
</GpopsSettings></OptimalControlSolverSettings></NMSMPipelineDocument>
"""
TIME_RANGE = "does not cover the problem's time range"


def _toy(shared: Path, tmp: Path, *, tool: str = "TrackingOptimizationTool", extra: str = "",
         edit: tuple[str, str] | None = None, data: Path | None = None) -> Path:
    """A current-schema toy-arm settings file (``data``: another folder of IKData and IDData)."""
    folder = shared / "treatment" / "toy_arm" / "tracking_optimization"
    (tmp / "solver.xml").write_text(SOLVER)
    text = TOY.format(tool=tool, tmp=tmp, data=folder, extra=extra)
    if data is not None:
        text = text.replace(str(folder / "preprocessed"), str(data))
    if edit is not None:
        assert edit[0] in text
        text = text.replace(*edit, 1)
    path = tmp / "settings.xml"
    path.write_text(text)
    return path


def _line_of(path: Path, text: str, after: int = 0) -> int:
    lines = path.read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if i > after and text in line)


def _error(path: Path, **options) -> str:
    with pytest.raises(InputError) as info, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(path, evaluate_only=True, **options)
    return str(info.value)


def _warnings(path: Path, **options) -> list[str]:
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        run_settings(path, evaluate_only=True, **options)
    return [str(w.message) for w in record]


# ----- term elements (c05, c06, c07, c11, c12) -----------------------------------------------
@pytest.mark.shared_data
def test_missing_required_term_element_names_the_term_and_the_element(shared_data: Path, tmp_path: Path) -> None:
    path = _toy(shared_data, tmp_path, edit=("<coordinate_list>r_elbow_flex</coordinate_list>\n", ""))
    line = _line_of(path, "<RCNLCostTerm>")
    message = _error(path)
    assert message == (f"{path}:{line}: <RCNLCostTerm>: term 'generalized_coordinate_tracking' has no <coordinate> "
                       "(expected <coordinate> or <coordinate_list>)")


@pytest.mark.shared_data
@pytest.mark.parametrize("old, new, element, text, expected", [
    ("<max_allowable_error>0.1<", "<max_allowable_error>-0.1<", "max_allowable_error",
     "term 'generalized_coordinate_tracking': 'max_allowable_error' must be > 0 (got -0.1)", "a number > 0"),
    ("<max_allowable_error>20<", "<max_allowable_error>0<", "max_allowable_error",
     "term 'inverse_dynamics_load_tracking': 'max_allowable_error' must be > 0 (got 0.0)", "a number > 0"),
    ("<min_error>-0.1<", "<min_error>0.2<", "min_error",
     "term 'kinetic_consistency': min_error 0.2 > max_error 0.1", "<min_error> <= <max_error>"),
])
def test_term_value_errors_name_their_element(shared_data: Path, tmp_path: Path, old: str, new: str, element: str,
                                              text: str, expected: str) -> None:
    path = _toy(shared_data, tmp_path, edit=(old, new))
    line = _line_of(path, new)
    assert _error(path) == f"{path}:{line}: <{element}>: {text} (expected {expected})"


@pytest.mark.shared_data
def test_name_errors_name_the_element_as_written(shared_data: Path, tmp_path: Path) -> None:
    path = _toy(shared_data, tmp_path, edit=("<coordinate_list>r_elbow_flex</coordinate_list>\n   <max",
                                             "<coordinate>r_elbow_flx</coordinate>\n   <max"))
    line = _line_of(path, "<coordinate>r_elbow_flx")
    assert _error(path).startswith(f"{path}:{line}: <coordinate>: term 'generalized_coordinate_tracking': "
                                   "coordinate 'r_elbow_flx' is not in the model")
    path = _toy(shared_data, tmp_path, edit=("<coordinate_list>r_elbow_flex</coordinate_list>\n   <max",
                                             "<coordinate_list>r_elbow_flx</coordinate_list>\n   <max"))
    line = _line_of(path, "<coordinate_list>r_elbow_flx")
    assert _error(path).startswith(f"{path}:{line}: <coordinate_list>: term 'generalized_coordinate_tracking': ")


# ----- default max_allowable_error (c04, c40) --------------------------------------------------
@pytest.mark.shared_data
def test_default_max_allowable_error_is_reported_once_per_term(shared_data: Path, tmp_path: Path) -> None:
    absent = ("<max_allowable_error>0.1</max_allowable_error>", "")
    path = _toy(shared_data, tmp_path, edit=absent)
    line = _line_of(path, "<RCNLCostTerm>")
    messages = [m for m in _warnings(path) if "max_allowable_error" in m]
    assert messages == [f"{path}:{line}: no <max_allowable_error> in term 'generalized_coordinate_tracking' "
                        "(default 1 used)"]
    path = _toy(shared_data, tmp_path, edit=("<max_allowable_error>0.1<", "<max_allowable_error><"))
    line = _line_of(path, "<max_allowable_error></")
    messages = [m for m in _warnings(path) if "max_allowable_error" in m]
    assert messages == [f"{path}:{line}: empty <max_allowable_error> in term 'generalized_coordinate_tracking' "
                        "treated as absent (default 1 used)"]
    # disabled terms are not read
    path = _toy(shared_data, tmp_path, edit=absent)
    path.write_text(path.read_text().replace("<is_enabled>true</is_enabled>", "<is_enabled>false</is_enabled>", 1))
    assert not [m for m in _warnings(path) if "max_allowable_error" in m]


# ----- initial guess on other times than the tracked data (c19) -------------------------------
def _shifted_guess(shared: Path, folder: Path, *, start: float, scale: float) -> Path:
    """The toy arm's IK and ID as an initial guess on times ``start + scale * t``."""
    data = shared / "treatment" / "toy_arm" / "tracking_optimization" / "preprocessed"
    for kind in ("IKData", "IDData"):
        table = read_storage(data / kind / "arm1.sto")
        (folder / kind).mkdir(parents=True, exist_ok=True)
        columns = {label: table.column(label) for label in table.labels}
        write_storage(folder / kind / "arm1.sto", table_from_columns(start + scale * table.time, columns))
    return folder


@pytest.mark.shared_data
@pytest.mark.parametrize("start, scale", [(1.0, 2.0), (1.0, 1.0), (0.0, 0.5)])
def test_initial_guess_on_other_times_is_reported(shared_data: Path, tmp_path: Path, start: float,
                                                  scale: float) -> None:
    guess = _shifted_guess(shared_data, tmp_path / "guess", start=start, scale=scale)
    path = _toy(shared_data, tmp_path)
    messages = [m for m in _warnings(path, initial_guess_directory=guess) if TIME_RANGE in m]
    end = start + scale * 5 / 3
    assert len(messages) == 1
    assert re.search(rf"initial guess IKData/arm1.sto, IDData/arm1.sto in {re.escape(str(guess))} spans "
                     rf"{start:g}-{end:.6g} s "
                     rf"\({end - start:.6g} s\); expected 0-1.66667 s \(1.66667 s, the time range of the tracked "
                     r"data .*/preprocessed/IKData/arm1.sto\) within one sample interval", messages[0])


@pytest.mark.shared_data
def test_initial_guess_on_the_tracked_times_is_not_reported(shared_data: Path, tmp_path: Path) -> None:
    path = _toy(shared_data, tmp_path)
    for guess in (_shifted_guess(shared_data, tmp_path / "same", start=0.0, scale=1.0),
                  _shifted_guess(shared_data, tmp_path / "late", start=0.0, scale=1.0 + 0.5 / 100)):
        assert not [m for m in _warnings(path, initial_guess_directory=guess) if TIME_RANGE in m]


@pytest.mark.shared_data
def test_free_final_time_guess_may_have_another_duration(shared_data: Path, tmp_path: Path) -> None:
    # a DO with a free final time starts from the guess's own duration (1.25 x the data's)
    extra = "\n <final_time_range>1 3</final_time_range>"
    path = _toy(shared_data, tmp_path, tool="DesignOptimizationTool", extra=extra)
    guess = _shifted_guess(shared_data, tmp_path / "longer", start=0.0, scale=1.25)
    assert not [m for m in _warnings(path, initial_guess_directory=guess) if TIME_RANGE in m or "final time" in m]
    # ... but not one taken from another part of a motion
    guess = _shifted_guess(shared_data, tmp_path / "later", start=1.0, scale=1.25)
    messages = [m for m in _warnings(path, initial_guess_directory=guess) if TIME_RANGE in m]
    assert len(messages) == 1 and "spans 1-3.08333 s (2.08333 s); expected 0-2.08333 s" in messages[0]


# ----- tracked ID without the column of a torque control (c16) ---------------------------------
@pytest.mark.shared_data
def test_missing_id_column_names_the_id_file(shared_data: Path, tmp_path: Path) -> None:
    data = _shifted_guess(shared_data, tmp_path / "data", start=0.0, scale=1.0)
    table = read_storage(data / "IDData" / "arm1.sto")
    write_storage(data / "IDData" / "arm1.sto", table_from_columns(table.time, {"other_moment": table.data[:, 0]}))
    path = _toy(shared_data, tmp_path, data=data)
    assert str(data / "IDData" / "arm1.sto") in _error(path)


# ----- upgrade warnings of a 0.1.0 file (P12) -------------------------------------------------
@pytest.mark.shared_data
def test_nmsm_run_prints_each_upgrade_warning_once(shared_data: Path) -> None:
    from nmsm.tools.dispatch import run_settings_file

    settings = shared_data / "treatment" / "toy_arm" / "tracking_optimization" / "TorqueDrivenTOSettings.xml"
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("default")  # as `nmsm run` (nmsm.cli.main)
        run_settings_file(settings, evaluate_only=True)
    counts = collections.Counter(str(w.message) for w in record if str(settings) in str(w.message))
    assert counts and max(counts.values()) == 1, counts


# ----- the tracked IK's unit header ----------------------------------------------------------------
@pytest.mark.shared_data
def test_tracked_motion_whose_degrees_header_looks_wrong_warns(shared_data: Path, tmp_path: Path) -> None:
    source = shared_data / "treatment" / "toy_arm" / "tracking_optimization" / "preprocessed"
    data = tmp_path / "data"
    for kind in ("IKData", "IDData"):
        (data / kind).mkdir(parents=True)
        (data / kind / "arm1.sto").write_text((source / kind / "arm1.sto").read_text())
    path = _toy(shared_data, tmp_path, data=data)
    assert not [m for m in _warnings(path) if "header may be wrong" in m]  # the tutorial's own file: silent
    ik = data / "IKData" / "arm1.sto"
    table = read_storage(ik)
    degrees = {label: table.column(label) * 180 / 3.141592653589793 for label in table.labels}
    write_storage(ik, table_from_columns(table.time, degrees))  # degrees written, header still radians
    messages = sorted({m for m in _warnings(path) if "header may be wrong" in m})  # read as tracked and as guess
    assert len(messages) == 1 and str(ik) in messages[0] and "r_elbow_flex" in messages[0]

"""A motion read for a model (``nmsm id``, ``markers``, ``muscle-analysis`` and their Python
functions): columns matched to the model's coordinates, the angle unit, the time range, the
sampling for low-pass filtering, muscle and trial names, paths handed to the OpenSim bridge."""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage, write_storage
from nmsm.model import load_model
from nmsm.model.id_tool import inverse_dynamics_of_motion, motion_coordinates
from nmsm.model.muscle_analysis import analyze_motion, check_trial_name, motion_poses

G10 = Path("opensim_gait10dof18musc")
MODEL = G10 / "gait10dof18musc_subject01.osim"
MOTION = G10 / "gait10dof18musc_subject_adjusted_Kinematics_q.sto"  # degrees; its step changes after 0.187 s
ARM = Path("jmp") / "toy_simple_arm" / "simple_arm.osim"


@pytest.fixture(scope="module")
def g10(shared_data: Path):
    return load_model(shared_data / MODEL)


def _motion(shared_data: Path, folder: Path, *, rows: int = 150, rename: dict[str, str] | None = None,
            drop: tuple[str, ...] = (), header_degrees: bool | None = None, name: str = "motion.sto") -> Path:
    """The first ``rows`` rows of the gait10dof18musc motion, written to ``folder / name`` with
    columns renamed or dropped and the ``inDegrees`` header possibly wrong."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a repeated row near its end is dropped
        table = read_storage(shared_data / MOTION)
    keep = [j for j, label in enumerate(table.labels) if label not in drop]
    labels = tuple((rename or {}).get(table.labels[j], table.labels[j]) for j in keep)
    table = Table(time=table.time[:rows], labels=labels, data=table.data[:rows, keep],
                  in_degrees=table.in_degrees if header_degrees is None else header_degrees, name="Coordinates")
    return write_storage(folder / name, table)


def _messages(record) -> str:
    return "\n".join(str(w.message) for w in record)


# ---- columns against the model's coordinates ---------------------------------------------
def test_motion_naming_no_model_coordinate_is_an_input_error(shared_data: Path, tmp_path: Path) -> None:
    arm = load_model(shared_data / ARM)
    path = _motion(shared_data, tmp_path)
    motion = read_storage(path)
    for compute in (lambda: motion_coordinates(arm, motion), lambda: inverse_dynamics_of_motion(arm, motion),
                    lambda: analyze_motion(shared_data / ARM, motion, model=arm)):
        with pytest.raises(InputError) as caught:
            compute()
        message = str(caught.value)
        assert str(path) in message and "no column names a coordinate of the model arm26" in message
        assert "r_elbow_flex" in message  # the coordinates expected


def test_renamed_column_warns_naming_both_sides(shared_data: Path, g10, tmp_path: Path) -> None:
    motion = read_storage(_motion(shared_data, tmp_path, rename={"knee_angle_r": "knee_bogus_r"}))
    with pytest.warns(UserWarning) as record:
        inverse_dynamics_of_motion(g10, motion)
    text = _messages(record)
    assert "coordinate(s) knee_angle_r of the model walk_subject01 have no column" in text
    assert "column(s) knee_bogus_r are not coordinates of the model" in text


def test_muscle_analysis_of_a_motion_lacking_most_coordinates_warns(shared_data: Path, g10, tmp_path: Path) -> None:
    drop = ("pelvis_tilt", "pelvis_tx", "pelvis_ty", "hip_flexion_r", "ankle_angle_r", "hip_flexion_l",
            "knee_angle_l", "ankle_angle_l")
    motion = read_storage(_motion(shared_data, tmp_path, rows=20, drop=drop))
    with pytest.warns(UserWarning, match=r"pelvis_tilt, pelvis_tx, pelvis_ty, hip_flexion_r, ankle_angle_r and 3 "
                                         r"more of the model walk_subject01 have no column"):
        analyze_motion(shared_data / MODEL, motion, model=g10, muscles=["soleus_r"])


def test_matching_motion_gives_no_warning(shared_data: Path, g10, tmp_path: Path) -> None:
    motion = read_storage(_motion(shared_data, tmp_path, rows=20))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        motion_coordinates(g10, motion)
        motion_poses(g10, motion)


def test_absent_rotational_coordinate_keeps_its_default_in_a_degree_file(shared_data: Path, tmp_path: Path) -> None:
    """The default (rad) of an absent rotational coordinate is given in the file's unit, so the
    callers' degree conversion of every rotational column leaves it at the default."""
    text = (shared_data / MODEL).read_text()
    anchor = '<Coordinate name="lumbar_extension">'
    head, tail = text.split(anchor)
    tail = tail.replace("<default_value>0</default_value>", "<default_value>0.3</default_value>", 1)
    model_file = tmp_path / "model.osim"
    model_file.write_text(head + anchor + tail)
    model = load_model(model_file)
    motion = read_storage(_motion(shared_data, tmp_path, rows=10, drop=("lumbar_extension",)))
    assert motion.in_degrees
    with pytest.warns(UserWarning, match="lumbar_extension"):
        values, missing = motion_coordinates(model, motion)
        poses = motion_poses(model, motion)
    column = model.coordinate_names.index("lumbar_extension")
    assert missing == ["lumbar_extension"]
    assert np.allclose(np.deg2rad(values[:, column]), 0.3)
    assert np.allclose(poses[:, column], 0.3)


# ---- angle unit ------------------------------------------------------------------------------
def test_degrees_without_the_header_warn_in_id_and_muscle_analysis(shared_data: Path, g10, tmp_path: Path) -> None:
    motion = read_storage(_motion(shared_data, tmp_path, rows=20, header_degrees=False))
    with pytest.warns(UserWarning, match=r"read with inDegrees=no.*header may be wrong \(inDegrees=yes\)"):
        inverse_dynamics_of_motion(g10, motion)
    with pytest.warns(UserWarning, match=r"header may be wrong \(inDegrees=yes\)"):
        analyze_motion(shared_data / MODEL, motion, model=g10, muscles=["soleus_r"])


# ---- time range --------------------------------------------------------------------------------
@pytest.mark.parametrize(("time_range", "expected"), [
    ((5.0, np.inf), r"no frame lies in the time range 5-inf s \(the file covers 0-0.149 s\)"),
    ((0.15, 0.05), r"the time range 0.15-0.05 s starts after it ends \(the file covers 0-0.149 s\)"),
    ((np.nan, np.inf), r"the time range nan-inf s has a bound that is not a number"),
])
def test_time_range_outside_the_motion_is_an_input_error(shared_data: Path, g10, tmp_path: Path, time_range,
                                                         expected: str) -> None:
    path = _motion(shared_data, tmp_path)
    with pytest.raises(InputError, match=expected) as caught:
        inverse_dynamics_of_motion(g10, read_storage(path), time_range=time_range)
    assert str(path) in str(caught.value)


def test_lowpass_of_unevenly_sampled_motion_names_where_the_step_changes(shared_data: Path, g10,
                                                                        tmp_path: Path) -> None:
    path = _motion(shared_data, tmp_path, rows=200)
    with pytest.raises(InputError, match=r"the time step changes at t = 0.187 s \(0.001 s -> 0.000646386 s\), "
                                         r"t = 0.187646 s .* and 9 more") as caught:
        inverse_dynamics_of_motion(g10, read_storage(path), lowpass_hz=6.0)
    assert str(path) in str(caught.value)


# ---- muscle and trial names ---------------------------------------------------------------------
def test_unknown_muscle_is_an_input_error_with_close_matches(shared_data: Path, g10, tmp_path: Path) -> None:
    motion = read_storage(_motion(shared_data, tmp_path, rows=10))
    with pytest.raises(InputError, match=r"muscles not in the model walk_subject01 \(.*gait10dof18musc_subject01"
                                         r"\.osim\): 'soleus_R' \(did you mean soleus_r"):
        analyze_motion(shared_data / MODEL, motion, model=g10, muscles=["soleus_R"])
    with pytest.raises(InputError, match=r"coordinates not in the model .*'knee_angel_r' \(did you mean knee_angle_r"):
        analyze_motion(shared_data / MODEL, motion, model=g10, coordinates=["knee_angel_r"])


@pytest.mark.parametrize("trial", ["../../escape", "a/b", "..", ".", "", "a\\b"])
def test_trial_name_must_be_a_plain_file_name(shared_data: Path, g10, tmp_path: Path, trial: str) -> None:
    with pytest.raises(InputError, match="is not a plain file name"):
        check_trial_name(trial)
    motion = read_storage(_motion(shared_data, tmp_path, rows=10))
    result = analyze_motion(shared_data / MODEL, motion, model=g10, muscles=["soleus_r"])
    out = tmp_path / "deep" / "MA"
    with pytest.raises(InputError, match="is not a plain file name"):
        result.write(out, trial)
    assert not (tmp_path / "escape").exists() and not out.exists()
    assert [p.name for p in result.write(out, "gait_1")][0] == "gait_1_Length.sto"


# ---- paths handed to the OpenSim bridge ---------------------------------------------------------
def test_relative_model_path_reaches_the_opensim_worker(shared_data: Path, bridge, tmp_path: Path,
                                                        monkeypatch) -> None:
    folder = tmp_path / "surr"
    folder.mkdir()
    (folder / "g10.osim").write_bytes((shared_data / MODEL).read_bytes())
    motion = read_storage(_motion(shared_data, tmp_path, rows=8))
    monkeypatch.chdir(tmp_path)
    result = analyze_motion(Path("surr") / "g10.osim", motion, muscles=["soleus_r"], engine="opensim", bridge=bridge)
    assert result.sources == {"soleus_r": "opensim"} and np.all(result.lengths > 0.1)


def test_motion_table_in_memory_is_named_in_warnings(g10) -> None:
    table = Table(time=np.arange(8) * 0.01, labels=("knee_angle_r", "extra"), data=np.zeros((8, 2)))
    with pytest.warns(UserWarning, match=r"^motion: .*column\(s\) extra are not coordinates"):
        motion_coordinates(g10, attrs.evolve(table, source=None))

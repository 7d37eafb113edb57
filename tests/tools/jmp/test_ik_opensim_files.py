"""OpenSim's own file forms, read as OpenSim reads them: a ``.trc`` whose header values are
separated by two tabs, a bare ``IKTaskSet`` file (or a setup naming one with ``file=``), and
IK tasks naming markers that the marker file or the model lacks (skipped with a warning).
Built from the shared gait2392 walking trial, which is OpenSim's ``subject01_walk1``."""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.storage import read_storage
from nmsm.io.trc import read_trc
from nmsm.model import load_model
from nmsm.tools.jmp.ik import run_ik_files
from nmsm.tools.jmp.ik_settings import read_ik_settings

WALK = "jmp/gait2392_walk_free"
#: tasks added to the shared task set: a marker of neither file, one of the model only, one of the file only
EXTRA_TASKS = {"R.HeelGround": 5.0, "R.Knee.Lat": 5.0, "R.Elbow": 5.0}
WINDOW = (3.2, 3.45)


def two_tab_trc(shared_data: Path, folder: Path) -> Path:
    """The walking trial with its header values separated by two tabs and a space, as
    OpenSim's 3D walking example ships them."""
    lines = (shared_data / WALK / "walk_free_01.trc").read_text().split("\n")
    lines[2] = "\t\t ".join(value.strip() for value in lines[2].split("\t"))
    path = folder / "walk_2tabs.trc"
    path.write_text("\n".join(lines))
    return path


def task_set_xml(shared_data: Path, extra: dict[str, float]) -> str:
    """The shared IK setup's ``<IKTaskSet>`` with ``extra`` marker tasks first."""
    text = (shared_data / WALK / "IKSettings.xml").read_text()
    block = re.search(r"<IKTaskSet>.*?</IKTaskSet>", text, re.S).group(0)
    tasks = "".join(f'<IKMarkerTask name="{n}"><apply>true</apply><weight>{w}</weight></IKMarkerTask>'
                    for n, w in extra.items())
    return block.replace("<objects>", "<objects>" + tasks, 1)


def setup_xml(shared_data: Path, task_set: str, marker_file: str) -> str:
    """The shared IK setup with ``task_set`` for its task set and ``marker_file``."""
    text = (shared_data / WALK / "IKSettings.xml").read_text()
    text = re.sub(r"<IKTaskSet>.*?</IKTaskSet>", lambda _: task_set, text, flags=re.S)
    return re.sub(r"<marker_file>.*?</marker_file>", f"<marker_file>{marker_file}</marker_file>", text)


# ----- .trc header ------------------------------------------------------------------------------
@pytest.mark.shared_data
def test_trc_header_values_separated_by_two_tabs(shared_data: Path, tmp_path: Path) -> None:
    """Refused before ("unknown units ''"); OpenSim 4.6 reads it (Units 'mm')."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # NumFrames 900 for 73 rows, in both files
        ours = read_trc(two_tab_trc(shared_data, tmp_path))
        original = read_trc(shared_data / WALK / "walk_free_01.trc")
    assert ours.units == "mm" and ours.data_rate == 60.0 and ours.orig_num_frames == 900
    assert ours == original


@pytest.mark.shared_data
def test_trc_header_with_a_value_missing_is_refused(shared_data: Path, tmp_path: Path) -> None:
    path = two_tab_trc(shared_data, tmp_path)
    lines = path.read_text().split("\n")
    lines[2] = lines[2].rsplit("\t\t", 1)[0]  # OrigNumFrames dropped
    path.write_text("\n".join(lines))
    with pytest.raises(InputError, match="line 3 has 7 values for the 8 keys of line 2") as info:
        read_trc(path)
    assert info.value.line == 3


@pytest.mark.shared_data
def test_trc_marker_names_one_tab_apart(shared_data: Path, tmp_path: Path) -> None:
    """Names separated by one tab (OpenSim 4.6 reads them in order: its TRCFileAdapter drops the
    empty cells of that line) read as the original; with a name missing they do not line up with
    NumMarkers and stay an error."""
    lines = (shared_data / WALK / "walk_free_01.trc").read_text().split("\n")
    names = [c for c in lines[3].split("\t")[2:] if c.strip()]
    lines[3] = "\t".join(["Frame#", "Time", *names])
    path = tmp_path / "one_tab.trc"
    path.write_text("\n".join(lines))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # NumFrames 900 for 73 rows, in both files
        assert read_trc(path) == read_trc(shared_data / WALK / "walk_free_01.trc")
    lines[3] = "\t".join(["Frame#", "Time", *names[1:]])
    path.write_text("\n".join(lines))
    with pytest.raises(InputError, match="names must be 3 columns apart"):
        read_trc(path)


# ----- IK task sets -----------------------------------------------------------------------------
@pytest.mark.shared_data
def test_bare_task_set_gives_the_setups_tasks(shared_data: Path, tmp_path: Path) -> None:
    """``<OpenSimDocument><IKTaskSet>`` (refused before: "no <InverseKinematicsTool> element"),
    with an ``<IKCoordinateTask>``; a setup naming the same file with ``<IKTaskSet file=...>``."""
    coordinate_task = ('<IKCoordinateTask name="lumbar_extension"><apply>true</apply><weight>10</weight>'
                       '<value_type>manual_value</value_type><value>-0.1</value></IKCoordinateTask>')
    block = task_set_xml(shared_data, {}).replace("</objects>", coordinate_task + "</objects>", 1)
    bare = tmp_path / "tasks.xml"
    bare.write_text(f'<?xml version="1.0" encoding="UTF-8" ?>\n<OpenSimDocument Version="40000">\n{block}\n'
                    "</OpenSimDocument>\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = read_ik_settings(shared_data / WALK / "IKSettings.xml")
    tasks = read_ik_settings(bare)
    assert tasks.marker_weights == full.marker_weights and len(tasks.marker_weights) == 31
    assert [(t.name, t.weight, t.value_type, t.value) for t in tasks.coordinate_tasks] == [
        ("lumbar_extension", 10.0, "manual_value", -0.1)]
    assert tasks.marker_file is None and tasks.time_range is None and tasks.accuracy is None
    setup = tmp_path / "setup.xml"
    setup.write_text(setup_xml(shared_data, '<IKTaskSet file="tasks.xml"/>', "walk.trc"))
    (tmp_path / "walk.trc").symlink_to(shared_data / WALK / "walk_free_01.trc")
    referenced = read_ik_settings(setup)
    assert referenced.marker_weights == full.marker_weights
    assert referenced.coordinate_tasks == tasks.coordinate_tasks
    assert referenced.accuracy == full.accuracy and referenced.marker_file == tmp_path / "walk.trc"


def test_a_file_with_neither_setup_nor_task_set_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "other.xml"
    path.write_text('<OpenSimDocument Version="40000"><ScaleTool/></OpenSimDocument>')
    with pytest.raises(InputError, match="neither an <InverseKinematicsTool> nor an <IKTaskSet>"):
        read_ik_settings(path)


@pytest.mark.shared_data
def test_nmsm_ik_with_a_bare_task_set(shared_data: Path, tmp_path: Path, capsys) -> None:
    bare = tmp_path / "tasks.xml"
    bare.write_text(f'<OpenSimDocument Version="40000">{task_set_xml(shared_data, {})}</OpenSimDocument>')
    out = tmp_path / "walk_ik.mot"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # NumFrames 900 for 73 rows
        code = main(["ik", str(shared_data / WALK / "subject01_gait2392_scaled.osim"),
                     str(shared_data / WALK / "walk_free_01.trc"), "--ik-settings", str(bare), "-o", str(out),
                     "--start", str(WINDOW[0]), "--end", str(WINDOW[1])])
    assert code == 0
    assert "31 markers" in capsys.readouterr().out
    assert read_storage(out).time[0] == pytest.approx(WINDOW[0], abs=1e-3)


@pytest.mark.shared_data
def test_tasks_naming_absent_markers_are_skipped_as_opensim_does(shared_data: Path, tmp_path: Path, bridge) -> None:
    """OpenSim 4.6 reads the two-tab ``.trc``, skips the tasks of markers that the file or the
    model lacks, and solves the rest; nmsm does the same with one warning naming them, and lands
    on OpenSim's coordinates (both at accuracy 1e-10)."""
    trc = two_tab_trc(shared_data, tmp_path)
    setup = tmp_path / "setup.xml"
    setup.write_text(setup_xml(shared_data, task_set_xml(shared_data, EXTRA_TASKS), trc.name))
    model_file = shared_data / WALK / "subject01_gait2392_scaled.osim"
    settings = read_ik_settings(setup)
    assert set(EXTRA_TASKS) <= set(settings.marker_weights)
    with pytest.warns(UserWarning) as record:
        ours = run_ik_files(model_file, ik_settings=settings, time_range=WINDOW, accuracy=1e-10)
    skipped = [str(w.message) for w in record if "skipped" in str(w.message)]
    assert len(skipped) == 1 and str(setup) in skipped[0]
    assert re.search(r"not in the marker file [^:]*walk_2tabs.trc: R.HeelGround \(close: R.Heel\), R.Knee.Lat",
                     skipped[0])
    assert "not in the model" in skipped[0] and "R.Elbow" in skipped[0]
    assert set(ours.marker_names) == {n for n, w in settings.marker_weights.items() if w > 0} - set(EXTRA_TASKS)
    theirs = bridge.call("opensim_inverse_kinematics", model=str(model_file), marker_file=str(trc),
                         marker_weights=settings.marker_weights, time_range=WINDOW, accuracy=1e-10)
    assert set(theirs["markers"]) == set(ours.marker_names)
    assert list(theirs["coordinates"]) == list(ours.coordinate_names)
    np.testing.assert_allclose(theirs["time"], ours.time)
    rotational = {c.name for c in load_model(model_file).coordinates if c.motion_type == "rotational"}
    for k, name in enumerate(ours.coordinate_names):
        if name not in ours.free_names or name in ours.insensitive_names:
            continue
        worst = float(np.abs(ours.q[:, k] - theirs["q"][:, k]).max())
        if name in rotational:
            assert np.degrees(worst) <= 1e-3, name
        else:
            assert worst <= 1e-5, name

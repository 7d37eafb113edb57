"""Clear errors for bad GCP input: time grids, force-plate columns, foot markers, one-segment
feet."""

from __future__ import annotations

import shutil
import warnings

import attrs
import numpy as np
import pytest

from nmsm.errors import InputError, ModelError
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.io.storage import format_storage, read_storage, table_from_columns, write_storage
from nmsm.tools.gcp.run import load_feet


@pytest.fixture
def case(synthetic_case, tmp_path):
    folder = tmp_path / "case"
    shutil.copytree(synthetic_case.folder, folder)
    return folder


def _load(folder, **replace):
    text = (folder / "settings.xml").read_text()
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    (folder / "settings.xml").write_text(text)
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(folder / "settings.xml"))
    return load_feet(settings)


def _rewrite(path, time, table):
    write_storage(path, table_from_columns(time, {k: np.interp(time, table.time, table.column(k))
                                                  for k in table.labels}, name="x"))


def test_grf_on_another_time_grid_is_resampled_with_a_warning(case):
    grf = read_storage(case / "grf.sto")
    _rewrite(case / "grf.sto", np.linspace(grf.time[0], grf.time[-1], 43), grf)  # 70 Hz: up to 7 ms off
    with pytest.warns(UserWarning, match="linearly interpolated"):
        feet, *_ = _load(case)
    assert feet[0].n_frames == grf.n_rows
    peak = grf.column("f1_vy").max()  # twice interpolated (101 -> 43 -> 61 samples): within 5 % of the peak
    np.testing.assert_allclose(feet[0].reactions.forces[:, 1], grf.column("f1_vy"), atol=0.05 * peak)


def test_grf_not_covering_the_window(case):
    grf = read_storage(case / "grf.sto")
    _rewrite(case / "grf.sto", grf.time[:40], grf)
    with pytest.raises(InputError, match="ground reactions cover") as err:
        _load(case)
    assert "grf.sto" in str(err.value)


def test_unevenly_sampled_motion(case):
    motion = read_storage(case / "ik.sto")
    time = motion.time.copy()
    time[10:] += 0.004
    write_storage(case / "ik.sto", table_from_columns(time, {k: motion.column(k) for k in motion.labels}, name="ik"))
    with pytest.raises(InputError, match="not evenly spaced") as err:
        _load(case)
    assert "ik.sto" in str(err.value)


def test_force_columns_not_in_the_file(case):
    with pytest.raises(InputError, match="f1_vq") as err:
        _load(case, **{"<force_columns>f1_vx f1_vy f1_vz": "<force_columns>f1_vx f1_vq f1_vz"})
    message = str(err.value)
    assert "settings.xml" in message and "<force_columns>" in message and "f1_vy" in message


def test_wrong_number_of_columns(case):
    with pytest.raises(InputError, match="3 columns"):
        _load(case, **{"<moment_columns>m1_x m1_y m1_z": "<moment_columns>m1_x m1_y"})


def test_foot_marker_missing_from_the_model(case):
    with pytest.raises(InputError, match="no marker 'R_Hee'") as err:
        _load(case, **{"<heel_marker>R_Heel": "<heel_marker>R_Hee"})
    assert "<heel_marker>" in str(err.value)


def test_model_without_a_two_segment_foot(case):
    model = (case / "foot.osim").read_text()
    model = model.replace('<PinJoint name="mtp_r">', '<WeldJoint name="mtp_r">').replace("</PinJoint>", "</WeldJoint>")
    start, end = model.index("<WeldJoint"), model.index("</WeldJoint>")
    block = model[start:end]
    block = block[: block.index("<coordinates>")] + block[block.index("</coordinates>") + len("</coordinates>"):]
    (case / "foot.osim").write_text(model[:start] + block + model[end:])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ModelError, match="two-segment foot") as err:
            _load(case)
    assert "foot.osim" in str(err.value) and "<hindfoot_body>" in str(err.value)


def test_read_only_results_folder_fails_before_optimizing(case):
    import os
    import time

    from nmsm.tools.gcp.run import run_settings

    (case / "results").mkdir()
    os.chmod(case / "results", 0o555)
    try:
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with pytest.raises(InputError, match="read-only"):
                run_settings(case / "settings.xml")
        assert time.perf_counter() - start < 5.0
    finally:
        os.chmod(case / "results", 0o755)


def test_force_columns_in_the_wrong_layout(case):
    """Vertical and fore-aft columns swapped in <force_columns>: the Y column is not the vertical force."""
    with pytest.raises(InputError, match="below the peak magnitude") as err:
        _load(case, **{"<force_columns>f1_vx f1_vy f1_vz": "<force_columns>f1_vy f1_vx f1_vz"})
    message = str(err.value)
    assert "grf.sto" in message and "<force_columns>" in message and "settings.xml" in message
    assert "Y (vertical) column 'f1_vx'" in message and "'f1_vy'" in message
    assert "expected force columns ordered X, Y, Z with Y the vertical (upward)" in message


def _rewrite_forces(path, **scale):
    grf = read_storage(path)
    columns = {k: grf.column(k) * scale.get(k, 1.0) for k in grf.labels}
    write_storage(path, table_from_columns(grf.time, columns, name="grf"))


def test_vertical_force_with_the_wrong_sign(case):
    """A plate reporting the force on the plate (vertical negative) is refused, naming the column."""
    _rewrite_forces(case / "grf.sto", f1_vy=-1.0)
    with pytest.raises(InputError, match=r"Y \(vertical\) column 'f1_vy' is not the vertical") as err:
        _load(case)
    assert "grf.sto" in str(err.value)
    _rewrite_forces(case / "grf.sto", f1_vx=0.0, f1_vz=0.0)  # no horizontal force to compare with: the sign decides
    with pytest.raises(InputError, match="'f1_vy' is not the vertical.*negative in 100% of the loaded frames"):
        _load(case)


def test_window_beyond_the_motion_warns(case):
    """gcp04: <end_time> past the motion's end is cut, and the warning says so."""
    motion = read_storage(case / "ik.sto")
    with pytest.warns(UserWarning) as record:
        feet, *_ = _load(case, **{"<end_time>0.6</end_time>": "<end_time>2.0</end_time>"})
    messages = [str(w.message) for w in record if "asks for" in str(w.message)]
    assert len(messages) == 1
    assert "settings.xml" in messages[0] and "<end_time>" in messages[0] and "<start_time>" not in messages[0]
    assert f"<end_time> asks for 0-2 s but the motion {case / 'ik.sto'} covers 0-{motion.time[-1]:g} s" in messages[0]
    assert feet[0].time[-1] == pytest.approx(motion.time[-1])


def test_window_inside_the_motion_is_silent(case):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        feet, *_ = _load(case)
    assert feet[0].n_frames > 2


def test_motion_header_in_the_wrong_unit_warns(case):
    """gcp07 / pre04: a degrees file marked radians (and the reverse) is named with the column and both units."""
    motion = read_storage(case / "ik.sto")
    rotational = [k for k in motion.labels if "rotation" in k or k.startswith("mtp")]
    degrees = motion.data.copy()
    for k in rotational:
        degrees[:, motion.labels.index(k)] = np.rad2deg(degrees[:, motion.labels.index(k)])
    (case / "ik.sto").write_text(format_storage(attrs.evolve(motion, data=degrees, in_degrees=False)))
    with pytest.warns(UserWarning, match=r"ik.sto: read with inDegrees=no, rotational column\(s\) '.*' .* rad "
                                         r"\(.* deg\), outside \[-2π, 2π\] rad.*header may be wrong"):
        _load(case)
    scaled = motion.data.copy()
    for k in rotational:
        scaled[:, motion.labels.index(k)] *= 3.0  # radians, moving enough to tell, marked degrees
    (case / "ik.sto").write_text(format_storage(attrs.evolve(motion, data=scaled, in_degrees=True)))
    with pytest.warns(UserWarning, match=r"ik.sto: inDegrees=yes, but every rotational column as written lies "
                                         r"within \[-π, π\].*look like radians"):
        _load(case)

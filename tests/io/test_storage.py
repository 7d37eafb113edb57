"""OpenSim .sto/.mot tables: every shared table, round trips, degrees, and bad input."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import (
    Table,
    center_of_pressure_columns,
    format_storage,
    parse_storage,
    read_storage,
    strip_load_suffix,
    table_from_columns,
    write_storage,
)

V1 = """Coordinates
version=1
nRows=3
nColumns=4
inDegrees=yes

Units are S.I. units
endheader
time\tknee_angle_r\tknee_angle_r_beta\tpelvis_tx
0.0\t10\t0.1\t1.0
0.1\t20\t0.2\t1.1
0.2\t30\t0.3\t1.2
"""

V3 = """DataType=double
version=3
OpenSimVersion=4.5
endheader
time f1_vy f1_px
0 10 0.5
0.5 0 NaN
1.0 12 0.7
"""


def _all_tables(root: Path) -> list[Path]:
    return sorted(p for ext in ("*.sto", "*.mot") for p in root.rglob(ext))


@pytest.mark.shared_data
def test_every_shared_table_reads_and_round_trips(shared_data: Path, tmp_path: Path) -> None:
    files = _all_tables(shared_data)
    assert len(files) > 800
    failures = []
    out = tmp_path / "copy.sto"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # stale nRows headers and the doubled last CMC row warn
        for path in files:
            table = read_storage(path)
            assert table.data.shape == (table.n_rows, len(table.labels)), path
            assert np.all(np.diff(table.time) > 0), path
            write_storage(out, table)
            again = read_storage(out)
            if again != table or again.name != (table.name or out.stem):
                failures.append(str(path))
    assert not failures, failures[:5]


@pytest.mark.shared_data
def test_shared_headers_of_both_styles(shared_data: Path) -> None:
    ik = read_storage(shared_data / "jmp/toy_simple_arm/simple_arm.mot")  # version=1, trailing tabs
    assert ik.in_degrees and ik.labels == ("r_elbow_flex",) and ik.n_rows == 120
    assert ik.column("r_elbow_flex")[1] == 1.0924
    grf = read_storage(shared_data / "gcp/uf_subject3_tutorial/preprocessed/GRFData/gait_1.sto")  # version=3
    assert not grf.in_degrees and grf.metadata["version"] == "3" and grf.n_rows == 101
    assert grf.time[0] == 0.5 and grf.column("ground_force_1_vy")[0] == 609.4522096287918


@pytest.mark.shared_data
def test_doubled_last_row_is_dropped_with_a_warning(shared_data: Path) -> None:
    path = shared_data / "opensim_gait10dof18musc/gait10dof18musc_subject_adjusted_Kinematics_q.sto"
    with pytest.warns(UserWarning, match="line\\(s\\) 2548 repeat"):
        table = read_storage(path)
    assert table.n_rows == 2536 and table.time[-1] == 2.499 and table.time[-2] == 2.498


def test_to_radians_converts_only_the_named_rotational_coordinates() -> None:
    table = parse_storage(V1)
    assert table.in_degrees and table.name == "Coordinates"
    converted = table.to_radians({"knee_angle_r", "hip_flexion_r"})
    assert not converted.in_degrees
    np.testing.assert_array_equal(converted.column("knee_angle_r"), np.deg2rad([10.0, 20.0, 30.0]))
    np.testing.assert_array_equal(converted.column("knee_angle_r_beta"), [0.1, 0.2, 0.3])  # coupled: stays
    np.testing.assert_array_equal(converted.column("pelvis_tx"), [1.0, 1.1, 1.2])
    assert converted.to_radians({"knee_angle_r"}) is converted  # already radians: unchanged
    back = converted.to_degrees({"knee_angle_r"})
    np.testing.assert_allclose(back.column("knee_angle_r"), [10.0, 20.0, 30.0], rtol=1e-15)


def test_tables_without_inDegrees_are_never_converted() -> None:
    table = parse_storage(V3, allow_nan={"f1_px"})
    assert table.to_radians({"f1_vy"}) is table


def test_write_as_opensim_storage(tmp_path: Path) -> None:
    table = table_from_columns(
        [0.0, 0.1], {"a": [1.0 / 3.0, math.nan], "b": [2.0, 1e-300]}, in_degrees=True, name="demo"
    )
    text = format_storage(table)
    lines = text.splitlines()
    assert lines[:6] == ["demo", "version=1", "nRows=2", "nColumns=3", "inDegrees=yes", "endheader"]
    assert lines[6] == "time\ta\tb"
    assert lines[7] == f"0.0\t{1.0 / 3.0!r}\t2.0" and lines[8] == "0.1\tNaN\t1e-300"
    path = write_storage(tmp_path / "demo.mot", table)
    again = read_storage(path, allow_nan={"a"})
    assert again == table and again.column("a")[0] == 1.0 / 3.0


def test_strip_load_suffix_and_load_columns() -> None:
    assert strip_load_suffix("knee_angle_r_moment") == "knee_angle_r"
    assert strip_load_suffix("knee_angle_r_beta_force") == "knee_angle_r_beta"
    assert strip_load_suffix("pelvis_tx") == "pelvis_tx"
    table = table_from_columns([0.0, 1.0], {"knee_angle_r_moment": [1, 2], "knee_angle_r_beta_force": [3, 4]})
    assert table.coordinate_labels() == ("knee_angle_r", "knee_angle_r_beta")
    np.testing.assert_array_equal(table.load_column("knee_angle_r_beta"), [3.0, 4.0])


def test_missing_column_names_file_and_close_matches(tmp_path: Path) -> None:
    path = tmp_path / "id.sto"
    path.write_text(V1)
    table = read_storage(path)
    with pytest.raises(InputError) as info:
        table.column("knee_angle_l")
    error = info.value
    assert error.file == str(path) and error.line == 9
    assert "knee_angle_l" in error.element and "knee_angle_r" in error.detail
    with pytest.raises(InputError, match="knee_angle_x"):
        table.columns(["pelvis_tx", "knee_angle_x"])


def test_nan_where_data_must_be_present_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "grf.sto"
    path.write_text(V3)
    with pytest.raises(InputError) as info:
        read_storage(path)
    assert info.value.line == 7 and info.value.element == "column 'f1_px'"


def test_nan_allowed_in_centre_of_pressure_columns(tmp_path: Path) -> None:
    path = tmp_path / "grf.sto"
    path.write_text(V3)
    table = read_storage(path, allow_nan=lambda label: label in center_of_pressure_columns([label]))
    assert math.isnan(table.column("f1_px")[1]) and table.column("f1_vy")[1] == 0.0


def test_nan_time_is_an_error_even_when_columns_allow_nan() -> None:
    text = V3.replace("0.5 0 NaN", "NaN 0 0.6")
    with pytest.raises(InputError, match="column 'time'"):
        parse_storage(text, allow_nan=lambda label: True)


def test_non_monotonic_time_is_an_error(tmp_path: Path) -> None:
    path = tmp_path / "ik.mot"
    path.write_text(V1.replace("0.2\t30", "0.05\t30"))
    with pytest.raises(InputError) as info:
        read_storage(path)
    assert info.value.line == 12 and "does not increase" in info.value.detail


def test_repeated_time_with_other_values_is_an_error() -> None:
    with pytest.raises(InputError, match="does not increase"):
        parse_storage(V1.replace("0.2\t30", "0.1\t30"))


def test_column_count_mismatch_names_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "ik.mot"
    path.write_text(V1.replace("0.1\t20\t0.2\t1.1", "0.1\t20\t0.2"))
    with pytest.raises(InputError) as info:
        read_storage(path)
    assert info.value.line == 11 and info.value.element.startswith("column 'pelvis_tx'")
    with pytest.raises(InputError, match="after the last label"):
        parse_storage(V1.replace("0.1\t20\t0.2\t1.1", "0.1\t20\t0.2\t1.1\t7"))


def test_header_column_count_must_match_labels() -> None:
    with pytest.raises(InputError, match="nColumns=5"):
        parse_storage(V1.replace("nColumns=4", "nColumns=5"))


def test_unreadable_tables(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="endheader"):
        parse_storage("time a\n0 1\n")
    with pytest.raises(InputError) as info:
        parse_storage(V1.replace("0.1\t20", "0.1\tabc"))
    assert info.value.line == 11 and info.value.element == "column 'knee_angle_r'"
    with pytest.raises(InputError, match="cannot read table"):
        read_storage(tmp_path / "missing.sto")
    with pytest.raises(InputError, match="duplicated column"):
        parse_storage(V3.replace("f1_px", "f1_vy"), allow_nan=lambda label: True)


def test_table_shape_is_checked() -> None:
    with pytest.raises(ValueError, match="expected"):
        Table(time=np.zeros(3), labels=("a", "b"), data=np.zeros((3, 3)))

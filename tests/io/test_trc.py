"""Marker files: every shared .trc, units, gaps, round trips and bad input."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.trc import MarkerTable, format_trc, parse_trc, read_trc, write_trc

TRC = (
    "PathFileType\t4\t(X/Y/Z)\tdemo.trc\n"
    "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n"
    "100\t100\t3\t2\tmm\t100\t1\t3\n"
    "Frame#\tTime\tA\t\t\tB\t\t\n"
    "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\n"
    "\n"
    "1\t0.00\t1000\t2000\t3000\t10\t20\t30\n"
    "2\t0.01\t1001\t2001\t3001\t\t\t\n"
    "3\t0.02\t1002\t2002\t3002\tNaN\tNaN\tNaN\t\t\n"
)


@pytest.mark.shared_data
def test_every_shared_marker_file_reads_and_round_trips(shared_data: Path, tmp_path: Path) -> None:
    files = sorted(shared_data.rglob("*.trc"))
    assert len(files) == 12
    for path in files:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # stale NumFrames headers
            table = read_trc(path)
        assert table.positions.shape == (table.n_frames, len(table.names), 3)
        assert np.all(np.diff(table.time) > 0)
        write_trc(tmp_path / "copy.trc", table)
        again = read_trc(tmp_path / "copy.trc")
        assert again.units == table.units and again.data_rate == table.data_rate
        np.testing.assert_allclose(again.positions, table.positions, rtol=1e-15, atol=0)
        write_trc(tmp_path / "metres.trc", table, units="m")
        assert read_trc(tmp_path / "metres.trc") == table  # exact in metres


@pytest.mark.shared_data
def test_millimetres_are_converted_and_gaps_kept(shared_data: Path) -> None:
    with pytest.warns(UserWarning, match="NumFrames=900"):
        walk = read_trc(shared_data / "jmp/gait2392_walk_free/walk_free_01.trc")
    assert walk.units == "mm" and walk.data_rate == 60.0 and walk.frames[0] == 185 and walk.time[0] == 3.067
    np.testing.assert_allclose(walk.marker(walk.names[0])[0], [0.59688123, 1.04468286, 0.11856002], rtol=1e-15)
    with pytest.warns(UserWarning, match="NumFrames=404"):
        gaps = read_trc(shared_data / "jmp/uf_subject3_tutorial/MarkerFiles/AnkleKneeHipGaitConcatenated_markers.trc")
    missing = np.isnan(gaps.positions).any(axis=2)
    assert missing.sum() == 101 and gaps.n_frames == 506  # one marker missing in 101 frames


def test_gaps_are_nan_not_errors() -> None:
    table = parse_trc(TRC)
    assert table.names == ("A", "B") and table.units == "mm"
    np.testing.assert_array_equal(table.marker("A")[0], [1.0, 2.0, 3.0])
    assert np.isnan(table.marker("B")[1:]).all() and table.marker("B")[0, 2] == 0.03
    text = format_trc(table, units="m")
    assert "\t\t\t" in text.splitlines()[7] or text.splitlines()[7].endswith("\t\t")
    assert parse_trc(text) == table


def test_select_between_and_missing_marker() -> None:
    table = parse_trc(TRC)
    assert table.select(["B"]).names == ("B",)
    assert table.between(0.005, 0.02).n_frames == 2
    with pytest.raises(InputError, match="close matches: A"):
        table.index("a")


def test_column_count_mismatch_names_line_and_column() -> None:
    with pytest.raises(InputError) as info:
        parse_trc(TRC.replace("2\t0.01\t1001\t2001\t3001\t\t\t\n", "2\t0.01\t1001\t2001\n"))
    assert info.value.line == 8 and "column 5 (marker 'A')" in info.value.element
    with pytest.raises(InputError) as info:
        parse_trc(TRC.replace("3\t0.02\t1002\t2002\t3002\tNaN\tNaN\tNaN\t\t\n", "3\t0.02\t1\t2\t3\t4\t5\t6\t7\n"))
    assert info.value.line == 9 and info.value.element == "column 9"


def test_non_monotonic_time() -> None:
    with pytest.raises(InputError) as info:
        parse_trc(TRC.replace("3\t0.02", "3\t0.005"))
    assert info.value.line == 9 and "Time" in info.value.element


def test_duplicated_marker_names() -> None:
    with pytest.raises(InputError, match="duplicated marker name"):
        parse_trc(TRC.replace("\tB\t", "\tA\t"))


def test_unknown_units_and_not_a_number() -> None:
    with pytest.raises(InputError, match="unknown units 'in'"):
        parse_trc(TRC.replace("\tmm\t", "\tin\t"))
    with pytest.raises(InputError) as info:
        parse_trc(TRC.replace("1001", "x"))
    assert info.value.line == 8 and "marker 'A' X" in info.value.element


def test_not_a_marker_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="PathFileType"):
        parse_trc("time a\n0 1\n")
    with pytest.raises(InputError, match="cannot read marker file"):
        read_trc(tmp_path / "none.trc")


def test_marker_table_checks_shapes() -> None:
    with pytest.raises(ValueError):
        MarkerTable(time=np.zeros(2), names=("a",), positions=np.zeros((2, 2, 3)))
    table = MarkerTable(time=[0.0, 0.5], names=("a",), positions=[[[1.0, 2.0, math.nan]], [[1.0, 2.0, 3.0]]])
    assert table.frames.tolist() == [1, 2]
    assert parse_trc(format_trc(table)) == table

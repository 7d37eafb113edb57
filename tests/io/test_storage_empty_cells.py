"""An empty cell in a tab-separated table is named by its own column (it was reported as the
row's last column missing: 'column RecFem2 (first missing value)' for a gap in GlutMaxMed)."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.storage import parse_storage, read_storage

TEXT = "emg\nversion=1\nendheader\ntime\tGlutMaxMed\tRecFem\tTibAnt\n0.0\t0.1\t0.2\t0.3\n0.1\t{a}\t{b}\t0.3\n"


def test_empty_cell_names_its_column(tmp_path: Path) -> None:
    path = tmp_path / "gait_1.sto"
    path.write_text(TEXT.format(a="", b="0.2"))
    with pytest.raises(InputError) as info:
        read_storage(path)
    error = info.value
    assert error.line == 6 and error.element == "column 'GlutMaxMed'" and str(error.file) == str(path)
    assert "empty cell in column 'GlutMaxMed'" in str(error)


def test_several_empty_cells_and_trailing_tabs() -> None:
    with pytest.raises(InputError, match="empty cells in columns 'GlutMaxMed', 'RecFem'"):
        parse_storage(TEXT.format(a="", b=" ").replace("0.3\n0.1", "0.3\t\t\n0.1"))


def test_trailing_tabs_alone_are_no_error_and_a_short_row_still_names_the_first_missing_value() -> None:
    table = parse_storage(TEXT.format(a="0.1", b="0.2").replace("\t0.3\n", "\t0.3\t\n"))
    assert table.n_rows == 2
    with pytest.raises(InputError) as info:
        parse_storage(TEXT.format(a="0.1", b="0.2").replace("0.1\t0.1\t0.2\t0.3", "0.1\t0.1\t0.2"))
    assert info.value.element.startswith("column 'TibAnt' (first missing value)")


@pytest.mark.parametrize("text", ["inf", "-Infinity"])
def test_infinite_values_are_refused_in_every_column(text: str) -> None:
    """'inf' parses as a number: it reached MTP as a traceback (bounds -nan) or a solver error."""
    with pytest.raises(InputError) as info:
        parse_storage(TEXT.format(a="0.1", b=text), allow_nan=lambda label: True)
    error = info.value
    assert error.line == 6 and error.element == "column 'RecFem'" and "infinite value" in str(error)

"""`.trc` reading: Units spelled as OpenSim's Units class also reads them (MM, millimeters, CM, METERS,
...) are accepted (nmsm refused them: "unknown units 'MM'"); an infinite marker value is an error."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.trc import read_trc


@pytest.mark.shared_data
@pytest.mark.parametrize("units, factor", [("MM", 1e3), ("millimeters", 1e3), ("CENTIMETERS", 1e2), ("METERS", 1.0)])
def test_opensim_unit_spellings(shared_data: Path, tmp_path: Path, units: str, factor: float) -> None:
    source = shared_data / "jmp" / "toy_simple_arm" / "simple_arm.trc"
    lines = source.read_text().splitlines()
    assert lines[2].split("\t")[4] == "m"
    values = lines[2].split("\t")
    values[4] = units
    lines[2] = "\t".join(values)
    for i in range(6, len(lines)):
        cells = lines[i].split("\t")
        lines[i] = "\t".join(cells[:2] + [repr(float(c) * factor) if c.strip() else c for c in cells[2:]])
    path = tmp_path / "m.trc"
    path.write_text("\n".join(lines) + "\n")
    np.testing.assert_allclose(read_trc(path).positions, read_trc(source).positions, rtol=1e-12, atol=1e-15)


def test_other_units_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "m.trc"
    path.write_text("PathFileType\t4\t(X/Y/Z)\tm.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n"
                    "60\t60\t1\t1\tinches\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n\n1\t0\t1\t2\t3\n")
    with pytest.raises(InputError, match="unknown units 'inches'"):
        read_trc(path)


def test_infinite_marker_value_is_refused(tmp_path: Path) -> None:
    """'inf' parses as a number; it was taken for a gap without a word."""
    path = tmp_path / "m.trc"
    path.write_text("PathFileType\t4\t(X/Y/Z)\tm.trc\nDataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n"
                    "60\t60\t2\t1\tm\nFrame#\tTime\tA\t\t\n\t\tX1\tY1\tZ1\n\n1\t0\t1\t2\t3\n2\t0.1\tinf\t2\t3\n")
    with pytest.raises(InputError) as info:
        read_trc(path)
    assert info.value.line == 8 and "marker 'A' X" in info.value.element and "'inf' is not a number" in str(info.value)

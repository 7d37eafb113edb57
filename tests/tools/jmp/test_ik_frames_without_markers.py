"""IK frames with no marker data (a gap of every marker) warn, naming the file and the times:
nothing determines their pose, the previous frame's is repeated (it was silent: the tutorial's
gait trial with three such frames got poses up to 4.6 degrees off the true one)."""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import numpy as np
import pytest

from nmsm.io.trc import read_trc
from nmsm.model import load_model
from nmsm.tools.jmp.marker_data import select_trial

ARM = Path("jmp") / "toy_simple_arm"


@pytest.mark.shared_data
def test_frames_without_markers_warn(shared_data: Path) -> None:
    model = load_model(shared_data / ARM / "simple_arm.osim")
    table = read_trc(shared_data / ARM / "simple_arm.trc")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # complete data: silent
        select_trial(table, model)
    positions = table.positions.copy()
    positions[30:33] = np.nan  # every marker missing in three frames
    positions[40, :2] = np.nan  # some markers missing: still determined
    gappy = attrs.evolve(table, positions=positions)
    with pytest.warns(UserWarning, match=r"simple_arm.trc: 3 frame\(s\) have no marker data \(t = 0.5, 0.516667, 0.533333 s\)"):
        select_trial(gappy, model)

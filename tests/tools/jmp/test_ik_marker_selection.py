"""``nmsm ik`` marker selection: an open-ended time range, a range beyond the data, model
markers the marker file lacks."""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.trc import read_trc
from nmsm.model import load_model
from nmsm.tools.jmp.ik import inverse_kinematics
from nmsm.tools.jmp.marker_data import frames_in_range, select_trial

ARM = Path("jmp") / "toy_simple_arm"


@pytest.fixture(scope="module")
def arm(shared_data: Path):
    return load_model(shared_data / ARM / "simple_arm.osim"), read_trc(shared_data / ARM / "simple_arm.trc")


def test_start_without_end_selects_from_start(arm) -> None:
    model, table = arm
    trial = select_trial(table, model, time_range=(1.0, np.inf))
    assert trial.time[0] >= 1.0 - 1e-9 and trial.time[-1] == table.time[-1]
    assert trial.n_frames == int(np.sum(table.time >= 1.0 - 1e-9))
    trial = select_trial(table, model, time_range=(-np.inf, 0.5))
    assert trial.time[0] == table.time[0] and trial.time[-1] <= 0.5 + 1e-9
    result = inverse_kinematics(model, table, time_range=(1.0, np.inf), check_marker_units=False)
    assert result.n_frames == int(np.sum(table.time >= 1.0 - 1e-9))


def test_start_beyond_the_data_is_an_input_error(arm) -> None:
    model, table = arm
    with pytest.raises(InputError, match=r"no frame of the marker file lies in the time range 10-inf s "
                                         r"\(the file covers 0-1.98333 s\)"):
        select_trial(table, model, time_range=(10.0, np.inf))
    assert not frames_in_range(table.time, np.nan, np.inf).any()
    assert frames_in_range(np.array([1e6, 1e6 + 1]), 1e6 + 1e-2, np.inf).tolist() == [False, True]


def test_model_markers_missing_from_the_file_warn(arm) -> None:
    model, table = arm
    names = list(table.names)
    names[0], names[5] = "bogus1", "bogus6"
    renamed = attrs.evolve(table, names=tuple(names))
    with pytest.warns(UserWarning) as record:
        trial = select_trial(renamed, model)
    text = "\n".join(str(w.message) for w in record)
    assert "model marker(s) r_humerus1, r_radius3" in text and "are not in the marker file" in text
    assert "the fit uses the other 4" in text and "the file's marker(s) bogus1, bogus6 are not markers" in text
    assert trial.names == ("r_humerus2", "r_humerus3", "r_radius1", "r_radius2")


def test_every_model_marker_present_or_named_weights_do_not_warn(arm) -> None:
    model, table = arm
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        select_trial(table, model)
        select_trial(attrs.evolve(table, names=("bogus1", *table.names[1:])), model, {"r_humerus2": 1.0})

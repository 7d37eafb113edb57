"""NCP's MTP activations are paired with the ID/MA rows by position and tracked: a file on
other times, or with activations below -0.01, is an InputError naming it (both ran silently:
an activation file 0.1 s late, a -0.3 activation tracked as a target); slightly negative
values are set to 0 as ``nmsm vaf`` does."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.ncp.run import run_settings


@pytest.fixture
def case(tmp_path):
    return make_synthetic_ncp_case(tmp_path, n_trials=2, n_points=41)


def _rewrite(path, time=None, column=None, change=None):
    table = read_storage(path)
    columns = {k: table.column(k).copy() for k in table.labels}
    if column is not None:
        columns[column] = change(columns[column])
    write_storage(path, table_from_columns(table.time if time is None else time(table.time), columns))


def test_mtp_activations_on_other_times_are_an_error(case) -> None:
    path = case.folder / "mtp" / "muscleActivations" / "trial_2_muscleActivations.sto"
    _rewrite(path, time=lambda t: t + 0.1)
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, print_level=0)
    message = str(info.value)
    assert str(path) in message and "column 'time'" in message and "trial 'trial_2': data row 1 is at" in message
    assert "IDData/trial_2" in message


def test_negative_mtp_activation_is_an_error_and_round_off_is_set_to_zero(case) -> None:
    path = case.folder / "mtp" / "muscleActivations" / "trial_1_muscleActivations.sto"
    label = read_storage(path).labels[0]

    def dip(depth):
        def change(values):
            values[5] = depth
            return values
        return change

    _rewrite(path, column=label, change=dip(-0.3))
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, print_level=0)
    message = str(info.value)
    assert str(path) in message and f"column '{label}'" in message and "negative activation -0.3 in data row 6" in message
    _rewrite(path, column=label, change=dip(-0.004))
    with pytest.warns(UserWarning, match="slightly negative activation"):
        outcome = run_settings(case.settings_file, print_level=0)
    assert outcome is not None

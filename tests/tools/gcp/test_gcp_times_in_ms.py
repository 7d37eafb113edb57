"""GCP with the motion's times in milliseconds: an InputError naming the motion file and its
time column (it was a traceback, 'OverflowError: cannot convert float infinity to integer',
from the kinematics filter's sampling rate rounding to 0 Hz)."""

from __future__ import annotations

import re
import shutil

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.gcp import bspline
from nmsm.tools.gcp.run import load_feet


def test_times_in_milliseconds_are_an_input_error(synthetic_case, tmp_path):
    folder = tmp_path / "case"
    shutil.copytree(synthetic_case.folder, folder)
    for name in ("ik.sto", "grf.sto"):
        table = read_storage(folder / name)
        write_storage(folder / name, table_from_columns(table.time * 1000.0, {k: table.column(k) for k in table.labels},
                                                        name=name))
    settings = folder / "settings.xml"
    text = settings.read_text()
    for element in ("start_time", "end_time"):
        text = re.sub(rf"<{element}>([^<]+)</{element}>", lambda m: f"<{element}>{float(m.group(1)) * 1000}</{element}>",
                      text)
    settings.write_text(text)
    with pytest.raises(InputError) as info:
        load_feet(GroundContactPersonalizationSettings.from_document(read_settings_document(settings)))
    message = str(info.value)
    assert "ik.sto" in message and "column 'time'" in message and "are the times in milliseconds?" in message


def test_filter_refuses_a_sampling_rate_rounding_to_zero():
    time = np.arange(30) * 11.0
    with pytest.raises(InputError, match="rounds to 0 Hz"):
        bspline.nodes_for_cutoff(time, np.sin(time)[:, None], 10.0)


def test_missing_ground_reaction_rows_are_named_as_a_gap(synthetic_case, tmp_path):
    """Rows missing from the GRF file used to be reported as 'sampled at other times'."""
    folder = tmp_path / "case"
    shutil.copytree(synthetic_case.folder, folder)
    grf = read_storage(folder / "grf.sto")
    keep = np.ones(grf.n_rows, dtype=bool)
    keep[20:25] = False
    write_storage(folder / "grf.sto", table_from_columns(grf.time[keep], {k: grf.column(k)[keep] for k in grf.labels},
                                                         name="grf"))
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(folder / "settings.xml"))
    with pytest.warns(UserWarning, match=r"grf.sto: ground reactions sampled at other times than the motion .*"
                                         r"\(rows are missing: a gap of [0-9.]+ s after [0-9.]+ s"):
        load_feet(settings)

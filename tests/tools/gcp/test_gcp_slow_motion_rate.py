"""GCP's kinematics filter estimates the motion's sampling rate as the original does (from the
first ten intervals, rounded to 10 Hz), so a motion sampled at 5 Hz or less (frames 0.2-0.5 s
apart, below the 0.5 s milliseconds check) rounds to 0 Hz. The error must say which rates work
(it said "sampled at 1 Hz or more", which a 4 Hz motion is) and name the motion file."""

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


def test_rate_rounding_to_zero_states_the_rate_needed():
    time = np.arange(30) * 0.25  # 4 Hz: (t[10] - t[0]) = 2.5 s -> round(0.4) * 10 = 0 Hz
    with pytest.raises(InputError) as info:
        bspline.nodes_for_cutoff(time, np.sin(time)[:, None], 1.0)
    message = str(info.value)
    assert "rounds to 0 Hz" in message and "more than 5 Hz" in message and "1 Hz or more" not in message


def test_slow_motion_names_the_motion_file(synthetic_case, tmp_path):
    folder = tmp_path / "case"
    shutil.copytree(synthetic_case.folder, folder)
    step = float(np.median(np.diff(read_storage(folder / "ik.sto").time)))
    scale = 0.25 / step  # frames 0.25 s apart
    for name in ("ik.sto", "grf.sto"):
        table = read_storage(folder / name)
        write_storage(folder / name, table_from_columns(table.time * scale, {k: table.column(k) for k in table.labels},
                                                        name=name))
    settings = folder / "settings.xml"
    text = settings.read_text()
    for element in ("start_time", "end_time"):
        text = re.sub(rf"<{element}>([^<]+)</{element}>",
                      lambda m: f"<{element}>{float(m.group(1)) * scale}</{element}>", text)
    settings.write_text(text)
    with pytest.raises(InputError) as info:
        load_feet(GroundContactPersonalizationSettings.from_document(read_settings_document(settings)))
    message = str(info.value)
    assert "rounds to 0 Hz" in message and "ik.sto" in message and "column 'time'" in message

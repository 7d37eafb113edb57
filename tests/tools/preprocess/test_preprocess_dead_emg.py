"""A dead raw EMG channel (the same value in every row) is an InputError naming the raw file
and the channel also in the original's across-channel demean mode (there it ran: the frame's
mean gave the dead channel the other channels' signal and changed every processed channel);
raw EMG times in milliseconds name the file and ask about the unit."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.preprocess.emg import process_emg


def _run(shared_data: Path, emg: Path, out: Path, pair: str = "0.3 0.8") -> None:
    pre = shared_data / "preprocessing" / "uf_subject3_tutorial" / "PreCompleted" / "input_data"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        main(["--traceback", "preprocess", "--time-pair", pair, "--prefix", "gait", "--model",
              str(pre / "UF_Subject_3_reduced_muscles.osim"), "--raw-emg", str(emg), "--emg-low-pass", str(3.5 / 1.1),
              "--ik", str(pre / "GaitTrial_IKResults.mot"), "--output", str(out)])


def _raw(shared_data: Path, tmp_path: Path, change) -> Path:
    table = read_storage(shared_data / "preprocessing" / "uf_subject3_tutorial" / "input_data" / "GaitTrial48_EMG.mot")
    time, columns = change(table.time, {k: table.column(k).copy() for k in table.labels})
    path = tmp_path / "emg.mot"
    write_storage(path, table_from_columns(time, columns))
    return path


@pytest.mark.shared_data
def test_dead_raw_channel_is_named_with_the_file(shared_data: Path, tmp_path: Path) -> None:
    def dead(time, columns):
        columns["GasMed"][:] = 0.0
        return time, columns

    emg = _raw(shared_data, tmp_path, dead)
    with pytest.raises(InputError) as info:
        _run(shared_data, emg, tmp_path / "out")
    message = str(info.value)
    assert message.startswith(f"{emg}: EMG columns: EMG channel(s) 'GasMed' carry no signal")
    assert "--emg-channels" in message and not (tmp_path / "out").exists()


@pytest.mark.shared_data
def test_raw_emg_times_in_milliseconds(shared_data: Path, tmp_path: Path) -> None:
    emg = _raw(shared_data, tmp_path, lambda time, columns: (time * 1000.0, columns))
    with pytest.raises(InputError, match=r"emg.mot: high-pass: .*sampled at 1.00025 Hz: are its times in milliseconds\?"):
        _run(shared_data, emg, tmp_path / "out")


def test_dead_channel_in_frame_mode():
    t = np.linspace(0, 1, 1001)
    noise = np.random.default_rng(2).standard_normal((t.size, 2))
    with pytest.raises(InputError, match="'Dead' carry no signal"):
        process_emg(t, np.column_stack([noise, np.full(t.size, 0.3)]), labels=("Sol", "TibAnt", "Dead"))

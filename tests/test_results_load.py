"""``nmsm.results.load``: every table of a results folder as a pandas DataFrame."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import nmsm.results
from nmsm.errors import InputError
from nmsm.io.storage import read_storage

pd = pytest.importorskip("pandas")

TO = Path("treatment") / "toy_arm" / "tracking_optimization" / "TorqueDrivenTOSettings.xml"


def _run(settings: Path, results: Path) -> None:
    from nmsm.tools.treatment.run import run_settings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(settings, results_directory=results, print_level=0)


def test_load_returns_every_table_of_a_treatment_folder(shared_data: Path, tmp_path: Path) -> None:
    results = tmp_path / "to"
    _run(shared_data / TO, results)
    _run(shared_data / TO, results)  # the first run's files go to superseded/, which load leaves out
    assert any((results / "superseded").iterdir())
    frames = nmsm.results.load(results)
    on_disk = sorted(p.relative_to(results).as_posix() for p in results.rglob("*.sto")
                     if "superseded" not in p.relative_to(results).parts)
    assert sorted(frames) == on_disk
    assert {"IKData/arm1.sto", "IDData/arm1.sto", "arm1_states.sto", "arm1_torqueControls.sto",
            "arm1_mocoTrajectory.sto"} <= set(frames)
    for name, frame in frames.items():
        table = read_storage(results / name)
        assert list(frame.columns) == list(table.labels), name
        np.testing.assert_array_equal(frame.index.to_numpy(), table.time)
        np.testing.assert_array_equal(frame.to_numpy(), table.data)
        assert frame.index.name == "time" and frame.attrs["file"] == str(results / name)
    assert frames["arm1_mocoTrajectory.sto"].attrs["header"]["num_states"] == "2"


def test_load_refuses_a_missing_folder(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="not a results folder"):
        nmsm.results.load(tmp_path / "nothing")


def test_load_without_pandas_says_how_to_install_it(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "a.sto").write_text("a\nendheader\ntime\tx\n0\t1\n", encoding="utf-8")
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r'pip install "nmsm\[pandas\]"'):
        nmsm.results.load(tmp_path)

"""Treatment solutions as Moco trajectory files, read by OpenSim's own ``MocoTrajectory``."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from nmsm.io.storage import read_storage, write_storage
from nmsm.tools.treatment.run import run_settings

TOY = Path("treatment") / "toy_arm"
STATES = ["/jointset/r_elbow/r_elbow_flex/value", "/jointset/r_elbow/r_elbow_flex/speed"]
CONTROLS = ["/forceset/tau_r_elbow_flex"]


def _run(settings: Path, results: Path, **options) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(settings, results_directory=results, print_level=0, **options)
    return results


def test_moco_trajectory_opens_in_opensim_and_compares(shared_data: Path, tmp_path: Path, bridge) -> None:
    to = _run(shared_data / TOY / "tracking_optimization" / "TorqueDrivenTOSettings.xml", tmp_path / "to")
    path = to / "arm1_mocoTrajectory.sto"
    read = bridge.call("moco_trajectory_summary", path=str(path), compare_to=str(path))
    assert read["state_names"] == STATES and read["control_names"] == CONTROLS
    states = read_storage(to / "arm1_states.sto")
    controls = read_storage(to / "arm1_torqueControls.sto")
    np.testing.assert_allclose(read["time"], states.time, rtol=0, atol=1e-12)
    np.testing.assert_allclose(read["states"], states.data, rtol=0, atol=1e-12)
    np.testing.assert_allclose(read["controls"], controls.data, rtol=0, atol=1e-9)
    assert read["rms"] == 0.0
    # a constant offset d in one of the 3 continuous columns: OpenSim's RMS is d / sqrt(3)
    table = read_storage(path)
    shifted = table.data.copy()
    shifted[:, 2] += 2.0
    write_storage(tmp_path / "shifted.sto", type(table)(time=table.time, labels=table.labels, data=shifted,
                                                         name=table.name, metadata=table.metadata))
    offset = bridge.call("moco_trajectory_summary", path=str(path), compare_to=str(tmp_path / "shifted.sto"))
    assert abs(offset["rms"] - 2.0 / np.sqrt(3.0)) < 1e-9, offset["rms"]
    # the verification of this tracking solution is a different trajectory of the same columns
    vo = _run(shared_data / TOY / "verification_optimization" / "TorqueDrivenVOSettings.xml", tmp_path / "vo",
              initial_guess_directory=to, tracked_quantities_directory=to)
    versus = bridge.call("moco_trajectory_summary", path=str(vo / "arm1_mocoTrajectory.sto"), compare_to=str(path))
    assert versus["state_names"] == STATES and 0.0 < versus["rms"] < 1.0, versus["rms"]

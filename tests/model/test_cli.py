"""``nmsm id`` and ``nmsm markers``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from nmsm.cli import main
from nmsm.io.storage import read_storage
from nmsm.io.trc import read_trc
from nmsm.model import load_model
from nmsm.model.id_tool import inverse_dynamics_of_motion

MTP = Path("mtp") / "uf_subject3_tutorial"


def test_id_command_writes_opensim_labels(shared_data: Path, tmp_path: Path, capsys) -> None:
    model = shared_data / MTP / "UF_Subject_3_reduced_muscles.osim"
    motion = shared_data / MTP / "preprocessed" / "IKData" / "gait_1.sto"
    out = tmp_path / "id.sto"
    assert main(["id", str(model), str(motion), "--lowpass", "6", "--start", "0.6", "-o", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    table = read_storage(out)
    expected = inverse_dynamics_of_motion(load_model(model), read_storage(motion), lowpass_hz=6.0, time_range=(0.6, np.inf))
    assert table.labels == expected.labels and table.labels[0] == "pelvis_tilt_moment"
    assert "knee_angle_r_beta_force" in table.labels and "pelvis_tx_force" in table.labels
    assert table.time[0] >= 0.6 - 1e-12
    assert np.abs(table.data - expected.data).max() <= 1e-9


def test_markers_command_matches_opensim(shared_data: Path, tmp_path: Path, bridge) -> None:
    pre = shared_data / "preprocessing" / "uf_subject3_tutorial" / "PreCompleted" / "input_data"
    model_path = pre / "UF_Subject_3_reduced_muscles.osim"
    motion_path = pre / "GaitTrial_IKResults.mot"  # degrees
    out = tmp_path / "markers.trc"
    assert main(["markers", str(model_path), str(motion_path), "--units", "mm", "-o", str(out)]) == 0
    markers = read_trc(out)
    model = load_model(model_path)
    motion = read_storage(motion_path)
    rows = [0, 50, motion.n_rows - 1]
    q = np.zeros((len(rows), len(model.coordinates)))
    for j, c in enumerate(model.coordinates):
        column = motion.column(c.name)[rows]
        q[:, j] = np.deg2rad(column) if c.motion_type == "rotational" else column
    ref = bridge.call("oracle_kinematics", path=str(model_path), q=q)
    order = [markers.names.index(n) for n in ref["marker_names"]]
    assert np.abs(markers.positions[rows][:, order] - ref["markers"]).max() <= 1e-9


def test_errors_are_reported_without_traceback(tmp_path: Path, capsys) -> None:
    assert main(["id", str(tmp_path / "none.osim"), str(tmp_path / "none.mot"), "-o", str(tmp_path / "x.sto")]) == 1
    assert "none.osim: model file not found" in capsys.readouterr().err


def test_markers_command_sets_poses_as_opensim(shared_data: Path, tmp_path: Path) -> None:
    """A motion whose locked coordinate (RCNL2024's pronation, locked at 90 deg) moves: the
    markers are those of the locked model, which IK and JMP can reach, and a warning says so."""
    import pytest

    model_path = shared_data / "models" / "RCNL2024.osim"
    motion_path = shared_data / "preprocessing/uf_subject3_tutorial/PreCompleted/input_data/GaitTrial_IKResults.mot"
    motion = read_storage(motion_path)
    data = motion.data.copy()
    data[:, motion.labels.index("pro_sup_r")] = 60.0  # degrees; the model holds it at 90
    moved = tmp_path / "moved.mot"
    from nmsm.io.storage import write_storage
    import attrs

    write_storage(moved, attrs.evolve(motion, data=data), name="Coordinates")
    for source, out in ((motion_path, tmp_path / "as_is.trc"), (moved, tmp_path / "moved.trc")):
        if source == moved:
            expected = (r"locked coordinate\(s\) mtp_angle_r \(108 frames\), mtp_angle_l \(108 frames\), "
                        r"pro_sup_r \(108 frames\) differ")
            with pytest.warns(UserWarning, match=expected):
                assert main(["markers", str(model_path), str(source), "-o", str(out)]) == 0
        else:
            assert main(["markers", str(model_path), str(source), "-o", str(out)]) == 0
    as_is, moved_markers = read_trc(tmp_path / "as_is.trc"), read_trc(tmp_path / "moved.trc")
    assert np.array_equal(as_is.positions, moved_markers.positions)

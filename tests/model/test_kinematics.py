"""Kinematics against OpenSim for every shared model, and the kinematics API."""

from __future__ import annotations

import zlib
from pathlib import Path

import casadi as cs
import numpy as np
import pytest
from model_testing import MODEL_FILES, random_poses

POSITION_TOLERANCE = 1e-9  # m
ROTATION_TOLERANCE = 1e-12


@pytest.mark.parametrize("relative", MODEL_FILES)
def test_markers_and_bodies_match_opensim(relative: str, shared_data: Path, bridge, model_cache) -> None:
    model, cm = model_cache(shared_data / relative)
    q = random_poses(model, cm, 6, np.random.default_rng(zlib.crc32(relative.encode())))
    ref = bridge.call("oracle_kinematics", path=model.source_file, q=q)
    order_m = [model.marker_names.index(n) for n in ref["marker_names"]]
    order_b = [list(model.bodies).index(n) for n in ref["body_names"]]
    markers = cm.marker_function().map(len(q))
    origins = cm.body_origins_function().map(len(q))
    ours_m = np.array(markers(q.T)).reshape(3, len(model.markers), len(q), order="F").transpose(2, 1, 0)
    ours_o = np.array(origins(q.T)).reshape(3, len(model.bodies), len(q), order="F").transpose(2, 1, 0)
    if model.markers:
        assert np.abs(ours_m[:, order_m] - ref["markers"]).max() <= POSITION_TOLERANCE
    assert np.abs(ours_o[:, order_b] - ref["origins"]).max() <= POSITION_TOLERANCE
    for i, name in enumerate(ref["body_names"]):
        rotation = cm.body_pose_function(name).map(len(q))(q.T)[0]
        rotation = np.array(rotation).reshape(3, 3, len(q), order="F").transpose(2, 0, 1)
        assert np.abs(rotation - ref["rotations"][:, i]).max() <= ROTATION_TOLERANCE, name


def test_pose_api_with_sx_mx_and_numbers(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    q = random_poses(model, cm, 1, np.random.default_rng(1))[0]
    rotation, origin = cm.body_pose("calcn_r", q)
    assert rotation.shape == (3, 3) and origin.shape == (3, 1)
    assert np.allclose(np.array(rotation) @ np.array(rotation).T, np.eye(3), atol=1e-14)
    local = np.array([0.1, -0.02, 0.03])
    point = np.array(cm.point_in_ground("calcn_r", local, q)).ravel()
    assert np.allclose(point, np.array(origin).ravel() + np.array(rotation) @ local, atol=1e-15)
    q_mx = cs.MX.sym("q", cm.n)
    f = cs.Function("f", [q_mx], [cm.point_in_ground("calcn_r", local, q_mx)])
    assert np.allclose(np.array(f(q)).ravel(), point, atol=1e-15)
    q_sx = cs.SX.sym("q", cm.n)
    g = cs.Function("g", [q_sx], [cm.body_pose("calcn_r", q_sx)[1]])
    assert np.allclose(np.array(g(q)), np.array(origin), atol=1e-15)
    marker = model.marker_names.index("R_Heel") if "R_Heel" in model.marker_names else 0
    m = model.markers[marker]
    expected = cm.point_in_ground(m.body, cm.kinematics.marker_in_body(marker), q)
    assert np.allclose(np.array(cm.marker_positions(q))[:, marker], np.array(expected).ravel(), atol=1e-15)


def test_point_velocity_and_com_are_consistent(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    rng = np.random.default_rng(2)
    q = random_poses(model, cm, 1, rng)[0]
    qd = rng.normal(size=cm.n)
    # dependent speeds consistent with the coupler, so positions along q + t qd stay valid
    local = np.array([0.05, 0.01, -0.02])
    velocity = np.array(cm.point_velocity_function("toes_r")(q, qd, local)).ravel()
    h = 1e-6
    ahead = np.array(cm.point_in_ground("toes_r", local, q + h * qd)).ravel()
    behind = np.array(cm.point_in_ground("toes_r", local, q - h * qd)).ravel()
    assert np.allclose(velocity, (ahead - behind) / (2 * h), rtol=0, atol=1e-8)
    marker_v = np.array(cm.marker_velocity_function()(q, qd))
    marker_fd = (np.array(cm.marker_positions(q + h * qd)) - np.array(cm.marker_positions(q - h * qd))) / (2 * h)
    assert np.abs(marker_v - marker_fd).max() <= 1e-8
    com = np.array(cm.center_of_mass_function()(q)).ravel()
    weighted = sum(b.mass * np.array(cm.point_in_ground(n, b.mass_center, q)).ravel() for n, b in model.bodies.items())
    assert np.allclose(com, weighted / model.total_mass(), atol=1e-15)


def test_orientation_angles_reproduce_rotation(shared_data: Path, model_cache) -> None:
    from nmsm.model.rotations import body_xyz

    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    q = random_poses(model, cm, 1, np.random.default_rng(3))[0]
    for body in ("pelvis", "femur_r", "calcn_l"):
        angles = np.array(cm.body_orientation_function(body)(q)).ravel()
        assert np.allclose(body_xyz(angles), np.array(cm.body_pose(body, q)[0]), atol=1e-14)


def test_frame_pose_of_offset_frame(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    q = random_poses(model, cm, 1, np.random.default_rng(4))[0]
    frame = model.frames["/jointset/knee_r/femur_r_offset"]
    rotation, origin = cm.frame_pose(frame.path, q)
    body_r, body_p = (np.array(v) for v in cm.body_pose("femur_r", q))
    assert np.allclose(np.array(origin).ravel(), body_p.ravel() + body_r @ frame.origin_in_base, atol=1e-15)
    assert np.allclose(np.array(rotation), body_r @ frame.rotation_in_base, atol=1e-15)


def test_coupled_coordinates_follow_the_chain_rule(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    cmap = cm.coordinates
    assert "knee_angle_r_beta" in cmap.dependent_names
    assert len(cmap.independent_names) + len(cmap.dependent_names) == cm.n
    rng = np.random.default_rng(5)
    qi = rng.uniform(-0.3, 0.3, cmap.n_independent)
    qi[cmap.independent_names.index("knee_angle_r")] = 0.7
    qdi = rng.normal(size=cmap.n_independent)
    qddi = rng.normal(size=cmap.n_independent)
    q, qd, qdd = (np.array(v).ravel() for v in cmap.expand(qi, qdi, qddi))
    assert np.array_equal(q[cmap.independent_indices], qi)
    h = 1e-5

    def position(t: float) -> np.ndarray:
        return np.array(cmap.expand_q(qi + qdi * t + 0.5 * qddi * t * t)).ravel()

    fd_velocity = (position(h) - position(-h)) / (2 * h)
    fd_acceleration = (position(h) - 2 * position(0.0) + position(-h)) / h**2
    dep = cmap.dependent_indices
    assert np.allclose(qd[dep], fd_velocity[dep], atol=1e-9)
    assert np.allclose(qdd[dep], fd_acceleration[dep], atol=2e-5)
    coupler = model.coupled_coordinates["knee_angle_r_beta"]
    assert q[model.coordinate_index("knee_angle_r_beta")] == pytest.approx(
        coupler.scale_factor * coupler.function.numeric(0.7))

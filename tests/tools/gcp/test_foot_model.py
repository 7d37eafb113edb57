"""Foot coordinates (Y-X-Z hindfoot angles, mirrored for the left foot) and the foot model's
point kinematics."""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.model.rotations import axis_angle
from nmsm.tools.gcp.foot_model import foot_coordinates, yxz_angles


def _rotation(axes, angles):
    r = np.eye(3)
    for axis, angle in zip(axes, angles):
        r = r @ axis_angle(np.asarray(axis, dtype=float), angle)
    return r


def test_yxz_roundtrip():
    angles = np.array([0.4, -0.3, 1.1])
    r = _rotation(([0, 1, 0], [1, 0, 0], [0, 0, 1]), angles)
    np.testing.assert_allclose(yxz_angles(r), angles, atol=1e-12)


def test_left_foot_uses_mirrored_axes():
    q_angles = np.array([0.2, -0.15, 0.5])
    r = _rotation(([0, -1, 0], [-1, 0, 0], [0, 0, 1]), q_angles)
    q = foot_coordinates(r, np.array([1.0, 0.05, -0.2]), 0.1, is_left=True)
    np.testing.assert_allclose(q[1:4], q_angles, atol=1e-12)
    np.testing.assert_allclose(q[[0, 4, 5, 6]], [0.1, 1.0, 0.05, -0.2])


def test_synthetic_foot_reproduces_its_coordinates(synthetic_case):
    """The synthetic model's joint to ground has the foot's axes: experimental foot
    coordinates equal the motion's coordinate values, and velocities are exact rates."""
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.io.storage import read_storage
    from nmsm.tools.gcp.run import load_feet

    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(synthetic_case.settings_file))
    feet, *_ = load_feet(settings)
    foot = feet[0]
    motion = read_storage(synthetic_case.motion_file)
    expected = motion.columns(["mtp_angle_r", "foot_rotation_y_r", "foot_rotation_x_r", "foot_rotation_z_r",
                               "foot_tx_r", "foot_ty_r", "foot_tz_r"])
    np.testing.assert_allclose(foot.coordinates, expected, atol=1e-12)
    f = foot.foot.marker_function()
    q, qd = expected[20], np.linspace(-0.3, 0.3, 7)
    h = 1e-6
    numeric = (np.array(f(q + h * qd, qd)[0]) - np.array(f(q - h * qd, qd)[0])) / (2 * h)
    np.testing.assert_allclose(np.array(f(q, qd)[1]), numeric, atol=1e-7)
    assert cs.DM(f(q, qd)[0]).shape == (3, 5)

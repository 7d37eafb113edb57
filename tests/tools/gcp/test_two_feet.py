"""Both feet: a mirrored left foot, separate time windows per foot, feet optimized together
(shared properties) or separately (known-answer synthetic case with two feet)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from nmsm.io.osimx import read_osimx
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.io.storage import read_storage
from nmsm.tools.gcp.run import load_feet, run_settings


@pytest.fixture(scope="module")
def two_feet(tmp_path_factory):
    from nmsm.examples.synthetic_gcp import write_synthetic_gcp

    return write_synthetic_gcp(tmp_path_factory.mktemp("synthetic_two_feet"), sides=("r", "l"))


def test_left_foot_is_mirrored_and_windows_differ(two_feet):
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(two_feet.settings_file))
    feet, *_ = load_feet(settings)
    motion = read_storage(two_feet.motion_file)
    right, left = feet
    assert left.foot.is_left and not right.foot.is_left
    assert left.time[0] == pytest.approx(0.5) and right.time[0] == pytest.approx(0.0)
    rows = np.flatnonzero(np.isclose(motion.time[:, None], left.time[None, :]).any(axis=1))
    names = ["mtp_angle_l", "foot_rotation_y_l", "foot_rotation_x_l", "foot_rotation_z_l", "foot_tx_l", "foot_ty_l",
             "foot_tz_l"]
    np.testing.assert_allclose(left.coordinates, motion.columns(names)[rows], atol=1e-12)
    # mirror image: same spring layout in the hindfoot frames with z negated, same order
    np.testing.assert_allclose(left.springs.locations * [1, 1, -1], right.springs.locations, atol=1e-12)
    # the left plate carries the left foot's load
    assert left.reactions.forces[:, 1].max() > 300 and right.reactions.forces[:, 1].max() > 300


def test_feet_together_share_properties(two_feet, tmp_path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run_settings(two_feet.settings_file, results_directory=tmp_path, feet="together",
                              update_motion=False, accept_unconverged=True)
    assert any("different time windows" in str(w.message) for w in caught)
    (group,) = result.groups
    state = group.state
    assert state.resting_spring_length == pytest.approx(two_feet.truth.resting_spring_length, abs=2e-5)
    assert state.damping_factor == pytest.approx(two_feet.truth.damping_factor, rel=0.02)
    assert np.median(np.abs(state.spring_constants / two_feet.spring_constants - 1)) < 0.01
    for foot in (1, 2):
        assert result.errors[foot]["Fy (N)"] < 0.05 and result.errors[foot]["Mz (N m)"] < 0.01
    surfaces = read_osimx(tmp_path / "foot_gcp.osimx").contact_surfaces
    assert [s.hindfoot_body for s in surfaces] == ["calcn_r", "calcn_l"]
    assert [s.is_left_foot for s in surfaces] == [False, True]
    np.testing.assert_array_equal([k.spring_constant for k in surfaces[0].springs],
                                  [k.spring_constant for k in surfaces[1].springs])
    assert (tmp_path / "foot_Foot_2_optimizedGroundReactions.sto").is_file()
    assert not (tmp_path / "GRFData").exists()  # combined files need a common window


@pytest.mark.slow
def test_feet_separately_by_default(two_feet, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = run_settings(two_feet.settings_file, results_directory=tmp_path, update_motion=False,
                              accept_unconverged=True)
    assert len(result.groups) == 2
    for group in result.groups:
        assert len(group.feet) == 1
        assert group.state.resting_spring_length == pytest.approx(two_feet.truth.resting_spring_length, abs=2e-5)
        assert np.median(np.abs(group.state.spring_constants / two_feet.spring_constants - 1)) < 0.01

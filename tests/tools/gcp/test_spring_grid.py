"""Marker-based spring placement and springs from an .osimx."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.osimx import GcpSpring
from nmsm.tools.gcp.spring_grid import SOLE_OUTLINE, inside_outline, layout_from_osimx, normalized_grid


def test_outline_and_grid():
    a, b = normalized_grid(5, 11)
    assert a.size == 55 and np.all((a > 0) & (a < 1) & (b > 0) & (b < 1))
    keep = inside_outline(a, b)
    assert keep.sum() == 47  # about 85 % of the grid (the original's shoe outline keeps 37)
    # full width at the ball of the foot, narrower heel
    assert inside_outline(np.array([0.02, 0.98]), np.array([0.7, 0.7])).all()
    assert not inside_outline(np.array([0.02]), np.array([0.02])).any()
    assert inside_outline(np.array([0.5, 0.5]), np.array([0.02, 0.98])).all()  # heel to toe marker
    assert (SOLE_OUTLINE[0, 0], SOLE_OUTLINE[-1, 0]) == (0.0, 1.0)


def test_placement_on_synthetic_foot(synthetic_case):
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.run import load_feet

    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(synthetic_case.settings_file))
    feet, *_ = load_feet(settings)
    foot = feet[0]
    springs = foot.springs
    assert springs.n_springs == inside_outline(*normalized_grid(5, 7)).sum() == 30
    assert set(springs.bodies) == {"calcn_r", "toes_r"}
    points = foot.foot.points_in_hindfoot(springs.points())
    np.testing.assert_allclose(points[:, 1], -0.04, atol=1e-12)  # default-pose height rule
    on_toes = np.array(springs.bodies) == "toes_r"
    assert points[on_toes, 0].min() > 0.17 > points[~on_toes, 0].max()  # split at the mtp axis (x = 0.17)
    heel, toe = -0.03, 0.17 + 0.065
    assert heel < points[:, 0].min() and points[:, 0].max() < toe
    assert springs.names[0] == "spring_marker_1"


def test_osimx_springs_must_be_on_the_foot(synthetic_case):
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.run import load_feet

    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(synthetic_case.settings_file))
    foot = load_feet(settings)[0][0].foot
    good = [GcpSpring("s1", "calcn_r", (0.1, -0.04, 0.0), 2000.0), GcpSpring("s2", "toes_r", (0.02, -0.03, 0.0), 2000.0)]
    layout = layout_from_osimx(good, foot)
    assert layout.bodies == ("calcn_r", "toes_r") and layout.locations.shape == (2, 3)
    with pytest.raises(InputError, match="on body 'tibia'"):
        layout_from_osimx([GcpSpring("s3", "tibia", (0, 0, 0), 1.0)], foot)

"""Patient 3 right foot (``gcp/patient3_right_foot``): 2023 settings upgraded on read, run
as they are: vertical force RMS <= 10 N, moment RMS <= 2 N m; the written ``.osimx``
compared with the original's 2023 output (old ``RCNLGroundContact`` layout)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from lxml import etree

from nmsm.io.osimx import read_osimx
from nmsm.tools.gcp.run import run_settings

pytestmark = pytest.mark.slow


def legacy_springs(path):
    """``(bodies, locations (n, 3), spring constants (n,), resting length)`` of a 2023 file."""
    root = etree.parse(str(path)).getroot()
    springs = root.findall(".//GCPSpring")
    bodies = [s.findtext("parent_body").strip() for s in springs]
    locations = np.array([[float(v) for v in s.findtext("location").split()] for s in springs])
    constants = np.array([float(s.findtext("spring_constant")) for s in springs])
    return bodies, locations, constants, float(root.findtext(".//resting_spring_length"))


@pytest.fixture(scope="module")
def patient3(shared_data, tmp_path_factory):
    folder = shared_data / "gcp" / "patient3_right_foot"
    out = tmp_path_factory.mktemp("patient3")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = run_settings(folder / "GCP_settings.xml", results_directory=out, accept_unconverged=True)
    return folder, result, caught


def test_upgraded_and_fitted(patient3):
    _, result, caught = patient3
    assert any("old settings schema" in str(w.message) for w in caught)
    assert len(result.settings.tasks) == 3 and result.settings.contact_surfaces[0].hindfoot_body == "calcn_r"
    errors = result.errors[1]
    print(errors)
    assert errors["Fy (N)"] <= 10.0
    assert max(errors["Mx (N m)"], errors["My (N m)"], errors["Mz (N m)"]) <= 2.0


def test_osimx_against_the_original(patient3):
    folder, result, _ = patient3
    ours = read_osimx(result.results_directory / "optModel_v6_correct_height_gcp.osimx").contact_surfaces[0]
    bodies, locations, constants, rest = legacy_springs(folder / "optModel_v6_correct_height_groundContactModel.osimx")
    # the 2023 file is a smoke-run output: every spring at the initial 2500 N/m and L0 = 0.05 m
    assert np.all(constants == 2500.0) and rest == 0.05
    ours_locations = np.array([s.location for s in ours.springs])
    ours_bodies = [s.parent_body for s in ours.springs]
    # same height rule (minus the default-pose hindfoot height) and the same two bodies
    np.testing.assert_allclose(ours_locations[np.array(ours_bodies) == "calcn_r", 1], locations[0, 1], atol=1e-9)
    assert set(ours_bodies) == set(bodies) == {"calcn_r", "toes_r"}
    # the sole regions overlap: hindfoot springs span within 3 cm of the original's x and z range
    hind, theirs = ours_locations[np.array(ours_bodies) == "calcn_r"], locations[np.array(bodies) == "calcn_r"]
    for axis in (0, 2):
        assert abs(hind[:, axis].min() - theirs[:, axis].min()) < 0.03
        assert abs(hind[:, axis].max() - theirs[:, axis].max()) < 0.03
    print(f"springs: nmsm {len(ours.springs)} ({ours_bodies.count('toes_r')} on the toes), original {len(bodies)} "
          f"({bodies.count('toes_r')}); L0 nmsm {ours.resting_spring_length:.4f} m; K nmsm "
          f"{np.min([s.spring_constant for s in ours.springs]):.0f}..{np.max([s.spring_constant for s in ours.springs]):.0f}")

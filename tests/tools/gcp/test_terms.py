"""GCP cost terms: registration, per-foot normalization, the neighbor term's exact
toe-angle formulation against a brute-force per-frame computation."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.registry import get_registry
from nmsm.core.term import SourceRef, TermSpec
from nmsm.core.registry import build_terms

GCP_TERMS = ("marker_position", "marker_slope", "rotation", "translation", "kinematic_periodicity", "vertical_grf",
             "vertical_grf_slope", "horizontal_grf", "horizontal_grf_slope", "ground_reaction_moment",
             "ground_reaction_moment_slope", "spring_constant_mean", "neighbor_spring_constant",
             "electrical_center_regularization", "force_plate_rotation_regularization")


def test_every_catalog_term_is_registered_for_gcp():
    registry = get_registry()
    for name in GCP_TERMS:
        assert "GCP" in registry.get("cost", name, "GCP").tools


def test_axes_of_electrical_center_regularization():
    spec = TermSpec("cost", "electrical_center_regularization",
                    {"type": "electrical_center_regularization", "is_enabled": "true", "axes": "x z",
                     "max_allowable_error": "0.01"}, SourceRef("s.xml", 3))
    (term,) = build_terms([spec], "GCP")
    assert term.axis_indices == [0, 2]
    bad = TermSpec("cost", "electrical_center_regularization",
                   {"type": "electrical_center_regularization", "is_enabled": "true", "axes": "xq"},
                   SourceRef("s.xml", 3))
    with pytest.raises(Exception, match="axes"):
        build_terms([bad], "GCP")


@pytest.fixture(scope="module")
def synthetic_feet(synthetic_case):
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.run import load_feet

    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(synthetic_case.settings_file))
    return settings, load_feet(settings)[0]


def test_neighbor_operator_matches_brute_force(synthetic_feet):
    from nmsm.tools.gcp.neighbors import NeighborOperator

    _, feet = synthetic_feet
    foot = feet[0]
    sigma = 0.05
    k = np.linspace(1500.0, 4200.0, foot.springs.n_springs)
    operator = NeighborOperator(foot.foot, foot.springs, sigma)
    theta = foot.coordinates[:, 0]
    ours = np.array(operator.deviation(cs.DM(theta).T, cs.DM(k)))
    positions = cs.Function("p", [foot.foot.q], [foot.foot.point_positions(foot.springs.points())])
    for t in (0, 30, 60):
        p = np.array(positions(foot.coordinates[t])).T
        d2 = ((p[:, None, :] - p[None, :, :]) ** 2).sum(axis=2)
        w = np.exp(-d2 / (2 * sigma**2))
        np.fill_diagonal(w, 0.0)
        expected = k - (w @ k) / w.sum(axis=1)
        np.testing.assert_allclose(ours[:, t], expected, rtol=1e-10, atol=1e-8)


def test_reduction_is_raw_over_error_and_root_length(synthetic_feet):
    """Each foot block: residuals (raw - c)/e/sqrt(len); neighbor: ((raw - c)/e)^4/sqrt(len)."""
    from nmsm.tools.gcp.problem import build_task_problem
    from nmsm.tools.gcp.state import GcpState
    from nmsm.tools.gcp.values import as_array

    settings, feet = synthetic_feet
    task = settings.tasks[0]
    specs = [TermSpec("cost", "vertical_grf", {"type": "vertical_grf", "is_enabled": "true",
                                               "max_allowable_error": "7", "error_center": "1"}),
             TermSpec("cost", "neighbor_spring_constant", {"type": "neighbor_spring_constant", "is_enabled": "true",
                                                           "max_allowable_error": "300"})]
    terms = build_terms(specs, "GCP")
    state = GcpState.initial(settings, feet)
    state.spring_constants = np.linspace(2000.0, 3000.0, feet[0].springs.n_springs)
    built = build_task_problem(feet, state, task, terms)
    costs = built.problem.term_costs(built.problem.initial_scaled())
    error = as_array(built.problem.evaluate(built.values[0].forces[1, :] - built.values[0].experimental_forces[1, :],
                                            built.problem.initial_scaled()))
    assert costs["vertical_grf"] == pytest.approx(np.mean(((error - 1) / 7) ** 2), rel=1e-10)
    deviation = as_array(built.problem.evaluate(built.context.neighbor_deviation(0), built.problem.initial_scaled()))
    assert costs["neighbor_spring_constant"] == pytest.approx(np.mean((deviation / 300) ** 8), rel=1e-10)

"""GPOPS-II solver settings: options without effect in nmsm warn only when a file sets them."""

from __future__ import annotations

import warnings

import attrs
import pytest

from nmsm.io.settings.solver import GpopsSettings
from nmsm.tools.treatment.solver_options import DESIGN_MAX_TOLERANCE, MAX_TOLERANCE, plan_from_settings


def test_options_left_at_their_defaults_give_no_warning() -> None:
    """(The default mesh method refines the mesh in GPOPS-II, which nmsm does not: that one
    warns at its default; the example's and tutorials' files set it to none.)"""
    gpops = attrs.evolve(GpopsSettings(), setup_mesh_method="none")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plan = plan_from_settings(gpops, source="solver.xml")
    assert plan.not_applicable == ()


def test_options_set_away_from_their_defaults_are_named_once() -> None:
    gpops = attrs.evolve(GpopsSettings(), setup_mesh_method="none", setup_derivatives_supplier="adigator",
                         integral_bound=10.0)
    with pytest.warns(UserWarning, match=r"solver.xml: GPOPS-II options without effect in nmsm: "
                                         r"setup_derivatives_supplier=adigator .*; integral_bound=10.0") as caught:
        plan = plan_from_settings(gpops, source="solver.xml")
    assert len(caught) == 1 and len(plan.not_applicable) == 2


def test_design_optimization_caps_the_tolerance_tighter() -> None:
    """TO/VO cap ``setup_nlp_tolerance`` at 1e-2 of the normalized objective, DO at 1e-6 (a
    design goal makes the objective at the guess far above its optimum); both say so."""
    gpops = attrs.evolve(GpopsSettings(), setup_mesh_method="none", setup_nlp_tolerance=1.0)
    with pytest.warns(UserWarning, match=r"setup_nlp_tolerance=1 is looser than nmsm applies; IPOPT uses tol=0.01"):
        assert plan_from_settings(gpops, source="solver.xml").ipopt["tol"] == MAX_TOLERANCE == 1e-2
    with pytest.warns(UserWarning, match=r"IPOPT uses tol=1e-06"):
        plan = plan_from_settings(gpops, source="solver.xml", max_tolerance=DESIGN_MAX_TOLERANCE)
    assert plan.ipopt["tol"] == DESIGN_MAX_TOLERANCE == 1e-6
    tight = attrs.evolve(gpops, setup_nlp_tolerance=1e-8)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert plan_from_settings(tight, max_tolerance=DESIGN_MAX_TOLERANCE).ipopt["tol"] == 1e-8

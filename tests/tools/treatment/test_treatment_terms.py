"""Every built-in TO/VO/DO term on the pendulum: builds, zero at perfect tracking, exact gradients."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.registry import get_registry
from nmsm.core.term import CostTerm

from treatment_pendulum_case import build_case

SAMPLE = {
    "coordinate": "q0", "load": "q0_moment", "marker": "tip_1", "axis": "x", "body": "link_1",
    "controller": "q0", "sequence": "xyz",
}
NEEDS_MUSCLES = {"muscle", "synergy", "synergies", "synergy_pairs", "force", "moment",
                 "hindfoot_body"}  # + contact: own test
# metabolic goals need muscles but name none (test_treatment_catalog_goals.py tests them)
NEEDS_MUSCLE_TYPES = ("metabolic_cost",)


def _builtin_terms() -> list[type]:
    registry = get_registry()
    out = []
    for kind in ("cost", "constraint"):
        for item in registry.items(kind):
            if item.distribution != "nmsm" or not item.tools & {"TO", "VO", "DO"}:
                continue
            if NEEDS_MUSCLES & set(item.cls.xml_fields()) or any(t in item.name for t in NEEDS_MUSCLE_TYPES):
                continue
            out.append(item.cls)
    return out


def _instance(cls: type):
    fields = cls.xml_fields()
    kwargs = {k: v for k, v in SAMPLE.items() if k in fields}
    if cls.type == "user_defined":
        if issubclass(cls, CostTerm):
            kwargs.update(function_name="footSpeedCost", cost_term_type="discrete",
                          options={"marker_name": "tip_1", "target_speed": "-2.5"})
        else:
            kwargs.update(function_name="footSpeedConstraint", constraint_term_type="terminal",
                          options={"marker_name": "tip_1"}, min_error=-10, max_error=10)
    if not issubclass(cls, CostTerm):
        kwargs.setdefault("min_error", -100.0)
        kwargs.setdefault("max_error", 100.0)
    return cls(**kwargs)


TERMS = _builtin_terms()


def test_the_registry_holds_the_tutorial_terms() -> None:
    names = {c.type for c in TERMS}
    for needed in ("generalized_coordinate_tracking", "inverse_dynamics_load_tracking", "controller_tracking",
                   "kinetic_consistency", "root_segment_residual_load", "final_marker_position_deviation",
                   "final_body_orientation_deviation", "final_marker_velocity_value", "generalized_coordinate_value",
                   "generalized_speed_deviation", "initial_generalized_speed_deviation", "user_defined"):
        assert needed in names


@pytest.mark.parametrize("cls", TERMS, ids=lambda c: f"{c.kind}:{c.type}")
def test_term_builds_and_has_exact_derivatives(cls: type) -> None:
    term = _instance(cls)
    tool = next(t for t in ("TO", "VO", "DO") if t in cls.tools)
    built = build_case([term], tool=tool, guess_scale=1.0, final_time=(0.8, 1.2) if tool == "DO" else None)
    problem = built.problem
    expression = problem.costs[0].residuals if problem.costs else problem.constraints[-1].expression
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    f = problem.function(expression)
    p = problem.parameter_values()
    value = np.asarray(f(x0, p)).ravel()
    assert np.all(np.isfinite(value))
    if "tracking" in cls.type or "deviation" in cls.type:
        # the guess is the tracked motion itself: deviations vanish up to spline interpolation
        # (inverse-dynamics references differ near the ends, where the natural-spline end
        # conditions of the loads and of the kinematics disagree)
        assert np.median(np.abs(value)) < 1e-3
        if "inverse_dynamics" not in cls.type:
            assert np.max(np.abs(value)) < 1e-3
    # exact Jacobian against central differences along a random direction
    rng = np.random.default_rng(0)
    direction = rng.standard_normal(x0.size) * 1e-3
    jac = cs.Function("j", [problem.scaled_vector(), problem.parameter_vector()],
                      [cs.jacobian(expression, problem.scaled_vector())])
    ad = np.asarray(jac(x0, p)) @ direction
    h = 1e-4
    fd = (np.asarray(f(x0 + h * direction, p)).ravel() - np.asarray(f(x0 - h * direction, p)).ravel()) / (2 * h)
    assert np.allclose(ad, fd, rtol=1e-4, atol=1e-7 * max(1.0, np.max(np.abs(fd))))

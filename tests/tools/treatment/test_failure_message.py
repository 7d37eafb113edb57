"""A failed treatment solve names the cost terms and constraints that are not finite."""

from __future__ import annotations

import numpy as np

from nmsm.core.problem import ConstraintStatus, Solution
from nmsm.tools.treatment.run import _not_finite


def _solution(term_costs: dict[str, float], constraints: tuple[ConstraintStatus, ...] = ()) -> Solution:
    return Solution({}, float("nan"), term_costs, False, "Invalid_Number_Detected", 0, 0.0, "ipopt", np.zeros(1),
                    constraints)


def test_non_finite_terms_and_constraints_are_named() -> None:
    constraints = (ConstraintStatus("kinetic_consistency:knee", 50, float("nan"), 0, None),
                   ConstraintStatus("limits", 10, 0.0, 2, None))
    text = _not_finite(_solution({"my_term:knee": float("nan"), "tracking:hip": 0.3, "other": float("inf")},
                                 constraints))
    assert text == "; not finite at the last iterate: my_term:knee, other, kinetic_consistency:knee"


def test_finite_values_add_nothing() -> None:
    assert _not_finite(_solution({"tracking:hip": 0.3})) == ""

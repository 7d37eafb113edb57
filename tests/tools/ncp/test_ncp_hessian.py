"""The structured exact Hessian equals CasADi's automatic Hessian of the same objective."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs
import numpy as np
import pytest

from nmsm.core.term import CostTerm, TermSpec
from nmsm.core.registry import build_terms
from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
from nmsm.tools.ncp.initial_guess import initial_guess
from nmsm.tools.ncp.loading import load_ncp
from nmsm.tools.ncp.problem import build_problem
from nmsm.tools.ncp.run import read_settings

ALL_TERMS = ("activation_minimization", "grouped_activations", "grouped_fiber_lengths", "bilateral_symmetry")


def _problem(tmp_path, symmetric: bool):
    case = make_synthetic_ncp_case(tmp_path, symmetric=symmetric, n_trials=2, n_points=31)
    settings = attrs.evolve(
        read_settings(case.settings_file),
        activation_muscle_groups=("RightLeg",),
        normalized_fiber_length_muscle_groups=("LeftLeg",),
    )
    setup = load_ncp(settings)
    extra = build_terms([TermSpec("cost", t, {"is_enabled": "true", "max_allowable_error": "0.2"}) for t in ALL_TERMS], "NCP")
    terms = list(setup.terms) + extra
    return build_problem(setup.inputs, terms, initial_guess(setup.inputs))


@pytest.mark.parametrize("symmetric", [True, False])
def test_structured_hessian_matches_automatic(tmp_path, symmetric) -> None:
    built = _problem(tmp_path, symmetric)
    problem = built.problem
    callback = built.ipopt_options()["casadi_options"]["hess_lag"]
    rng = np.random.default_rng(5)
    x = problem.initial_scaled() * rng.uniform(0.3, 1.7, problem.n_variables) + rng.uniform(0, 0.1, problem.n_variables)
    n_g = problem.constraint_vector()[0].numel()
    ours = np.asarray(cs.DM(callback(x, problem.parameter_values(), 2.5, np.zeros(n_g))).full())
    xs = problem.scaled_vector()
    automatic = cs.Function("h", [xs, problem.parameter_vector()], [cs.triu(cs.hessian(problem.objective(), xs)[0])])
    reference = 2.5 * np.asarray(automatic(x, problem.parameter_values()).full())
    assert np.abs(ours - reference).max() <= 1e-10 * max(1.0, np.abs(reference).max())


@attrs.frozen(kw_only=True)
class _SquaredActivations(CostTerm):
    """Not affine in the activations: the structured Hessian must decline it."""

    type: ClassVar[str] = "squared_activation_test_term"
    tools: ClassVar[frozenset[str]] = frozenset({"NCP"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.untracked_activations() ** 2


def test_non_affine_term_falls_back_to_automatic_hessian(tmp_path) -> None:
    case = make_synthetic_ncp_case(tmp_path, n_trials=1, n_points=21)
    setup = load_ncp(read_settings(case.settings_file))
    built = build_problem(setup.inputs, [*setup.terms, _SquaredActivations()], initial_guess(setup.inputs))
    with pytest.warns(UserWarning, match="not affine"):
        assert built.ipopt_options() == {}

"""The lifted chain-rule Jacobian (back end ``lifted_least_squares``) equals CasADi's Jacobian
through the kinematic coefficients, and the residuals are the same."""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.core.registry import build_terms
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.tools.gcp.problem import build_task_problem
from nmsm.tools.gcp.run import load_feet
from nmsm.core.backends.sparse import dm_to_csc
from nmsm.core.backends.lifted_least_squares import LiftedResiduals
from nmsm.tools.gcp.state import GcpState


def test_lifted_jacobian_is_exact(synthetic_case):
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(synthetic_case.settings_file))
    feet = load_feet(settings)[0]
    task = settings.tasks[0]
    terms = build_terms(list(task.cost_terms), "GCP")
    state = GcpState.initial(settings, feet)
    state.resting_spring_length = 0.004
    rng = np.random.default_rng(1)
    state.coefficients = [c + 0.01 * rng.standard_normal(c.shape) for c in state.coefficients]
    lifted_task = build_task_problem(feet, state, task, terms, lift=True)
    direct_task = build_task_problem(feet, state, task, terms, lift=False)
    assert set(lifted_task.problem.lifted) == {"q_1", "qdot_1"} and not direct_task.problem.lifted
    direct = direct_task.problem
    xs, ps = direct.scaled_vector(), direct.parameter_vector()
    r = direct.residual_vector()
    f = cs.Function("f", [xs, ps], [r, cs.jacobian(r, xs)])
    lifted = LiftedResiduals(lifted_task.problem)
    for _ in range(2):
        x = direct.initial_scaled() + 0.01 * rng.standard_normal(direct.n_variables)
        r_direct, j_direct = f(x, direct.parameter_values())
        np.testing.assert_allclose(lifted.residuals(x), np.array(r_direct).ravel(), rtol=1e-12, atol=1e-10)
        difference = lifted.jacobian(x) - dm_to_csc(j_direct)
        assert abs(difference).max() <= 1e-9 * max(1.0, abs(dm_to_csc(j_direct)).max())


def test_single_threaded_blas_sets_and_restores_thread_counts():
    from nmsm.core.blas_threads import _controls, single_threaded_blas

    controls = _controls()
    before = [get() for _, get in controls]
    with single_threaded_blas():
        assert all(get() == 1 for _, get in controls)
    assert [get() for _, get in controls] == before

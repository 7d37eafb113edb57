"""Known answer: true parameters -> synthetic EMG and moments -> MTP recovers them."""

from __future__ import annotations

import pytest

from nmsm.examples.synthetic_mtp import TOLERANCES, make_synthetic_mtp, recover, recovery_errors


@pytest.mark.parametrize("n_muscles, n_trials, seed", [(3, 2, 3), (5, 3, 11)])
def test_recovers_true_parameters(n_muscles, n_trials, seed):
    """IPOPT is a local method and starts at the original's initial values, so a seed can
    end in a local minimum: measured 2026-11-25 over 120 seeds of 3-6 muscles, none with
    ``TASK_MU_INIT`` (1718 iterations in all); with IPOPT's default barrier start 1 (5 muscles,
    3 trials, seed 23) and 2 with per-frame fiber-length rows. The seeds here recover the truth."""
    case = make_synthetic_mtp(n_muscles=n_muscles, n_trials=n_trials, seed=seed)
    estimate, cost, _ = recover(case)
    errors = recovery_errors(case, estimate)
    for block, tolerance in TOLERANCES.items():
        assert errors[block] <= tolerance, (block, errors[block])
    assert cost <= 1e-12


def test_task_with_fixed_lengths_outside_the_limits_warns_and_solves():
    """With l_o and l_ts fixed the fiber-length limits are constants: a task starting outside
    them must name the muscles and still fit the other parameters (IPOPT used to stop with
    'Infeasible_Problem_Detected')."""
    import attrs
    import numpy as np

    from nmsm.core.registry import get_registry
    from nmsm.tools.mtp.evaluation import initial_fiber_lengths
    from nmsm.tools.mtp.problem import MtpState, TaskSettings, build_task_problem

    case = make_synthetic_mtp(n_muscles=3, n_trials=2, seed=3)
    muscles = case.data.muscles
    short = muscles.tendon_slack_length.copy()
    short[1] -= 0.5 * muscles.optimal_fiber_length[1]  # muscle_1's fibers now longer than 1.3 l_o
    data = attrs.evolve(case.data, muscles=attrs.evolve(muscles, tendon_slack_length=short))
    term = get_registry().get("cost", "inverse_dynamics_joint_moment", "MTP")(max_allowable_error=0.01)
    task = TaskSettings(cost_terms=(term,), optimize={"optimal_fiber_length_scale": False,
                                                      "tendon_slack_length_scale": False})
    # muscle_1's range printed with its maximum above 1.3 (1.54 here)
    with pytest.warns(UserWarning, match=r"muscle_1 \(1\.\d\d\.\.1\.[4-9]\d\).*the limits apply from the first task"):
        problem, _ = build_task_problem(data, MtpState.initial(data), task, initial_fiber_lengths(data))
    solution = problem.solve("ipopt", max_iter=200, print_level=0)
    assert solution.success, solution.status
    assert np.isfinite(solution.cost)

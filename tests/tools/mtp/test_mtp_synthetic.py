"""Known answer: true parameters -> synthetic EMG and moments -> MTP recovers them."""

from __future__ import annotations

import pytest

from nmsm.examples.synthetic_mtp import TOLERANCES, make_synthetic_mtp, recover, recovery_errors


@pytest.mark.parametrize("n_muscles, n_trials, seed", [(3, 2, 3), (5, 3, 11)])
def test_recovers_true_parameters(n_muscles, n_trials, seed):
    case = make_synthetic_mtp(n_muscles=n_muscles, n_trials=n_trials, seed=seed)
    estimate, cost, _ = recover(case)
    errors = recovery_errors(case, estimate)
    for block, tolerance in TOLERANCES.items():
        assert errors[block] <= tolerance, (block, errors[block])
    assert cost <= 1e-12

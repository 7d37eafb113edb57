"""Patient 3, both legs and trunk (148 muscles, 6 + 6 synergies), bilateral symmetry on.

The 2023-schema settings file ``newNCPSettingsFile.xml`` (trials 1 and 2, all five NCP
terms) is read as it is (upgraded in memory); symmetry is switched on by option and the
results go to a temporary folder. MTP's 2023 ``mtpResults/model.osimx`` supplies the
length scale factors of the 90 leg muscles.
"""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.tools.ncp.forces import moment_gains
from nmsm.tools.ncp.run import run_settings


@pytest.fixture(scope="module")
def run(shared_data, tmp_path_factory):
    settings = shared_data / "ncp" / "patient3_bilateral_trials1to3" / "newNCPSettingsFile.xml"
    with pytest.warns(UserWarning):
        result = run_settings(settings, results_directory=tmp_path_factory.mktemp("p3"), enforce_bilateral_symmetry=True,
                              print_level=0)
    m = result.metrics
    print(f"\npatient 3 bilateral: {result.solver.status}, {result.solver.iterations} iterations, "
          f"wall {result.wall_time:.1f} s, cost {result.costs['total']:.4f}")
    print("| coordinate | moment RMS (N·m) |\n|---|---|")
    for c, v in zip(m.coordinates, m.moment_rms):
        print(f"| {c} | {v:.3f} |")
    print(f"| mean | {m.mean_moment_rms:.3f} |\nactivation RMS {m.activation_rms_pooled:.4f}, VAF {100 * m.activation_vaf:.2f} %")
    return result


def test_converges(run) -> None:
    assert run.solver.success, run.solver.status
    assert run.setup.inputs.layout.n_muscles == 148 and len(run.setup.inputs.mtp_muscles) == 90
    assert [g.n_synergies for g in run.setup.inputs.layout.groups] == [6, 6]
    assert max(c.max_violation for c in run.solver.constraints) < 1e-8


def test_activation_rms_within_005(run) -> None:
    assert run.metrics.activation_rms_pooled <= 0.05


def test_vectors_are_shared_between_sides(run) -> None:
    layout = run.solution.layout
    right, left = run.solution.group_weights(0), run.solution.group_weights(1)
    order = [layout.groups[0].muscles.index(m[:-2] + "_r") for m in layout.groups[1].muscles]
    assert np.array_equal(left, right[:, order])
    assert np.allclose(right.max(axis=1), 1.0)


def test_moments_better_than_mtp_activations_alone(run) -> None:
    """NCP's synergy activations fit the ID moments better than MTP's activations (trunk at 0)."""
    inputs = run.setup.inputs
    idx = list(inputs.mtp_indices)
    squared, frames = 0.0, 0
    for trial in inputs.trials:
        a = np.zeros((trial.n_points, inputs.layout.n_muscles))
        a[:, idx] = trial.mtp_activations
        squared = squared + np.sum((moment_gains(trial, inputs.muscles, inputs.v_max_factor).moments(a) - trial.moments) ** 2, axis=0)
        frames += trial.n_points
    mtp_rms = np.sqrt(squared / frames)
    assert run.metrics.mean_moment_rms < float(np.mean(mtp_rms))

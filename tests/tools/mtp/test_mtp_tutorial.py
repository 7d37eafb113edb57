"""Tutorial subject 3 (``MTPSettingsV1..V3.xml``) run as they are, compared with the original.

Criteria: our final cost <= the original's solution scored by our cost function (its
``*_mtp.osimx`` on our task-start data; with SynX its synergy weights are fitted), every
coordinate's moment RMS <= 1.1 x the original's (its ``Analysis`` folder), parameters in
bounds, and the output layout of tools.md §4.6. All three run in the default suite
(measured 2026-11-25: V3 1.2 s, V1 and V2 3.3 s each, with MTLI).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from nmsm.core.convergence import read_convergence_table
from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage
from nmsm.plots.mtp import is_mtp_results, plot_mtp_results
from nmsm.tools.mtp.report import (
    ComparisonRow,
    comparison_table,
    moment_rms,
    parameters_from_osimx,
    parameters_within_bounds,
    score_parameters,
)
from nmsm.tools.mtp.run import run_settings


def _run(shared_data, tmp_path_factory, version):
    folder = shared_data / "mtp" / "uf_subject3_tutorial" / "CompletedSettingsFiles"
    out = tmp_path_factory.mktemp(f"mtp_{version}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        outcome = run_settings(folder / f"MTPSettings{version}.xml", results_directory=out)
    original = folder / f"MTPResults{version}"
    data, state = parameters_from_osimx(original / "UF_Subject_3_reduced_muscles_mtp.osimx", outcome.start_data)
    score, _ = score_parameters(data, state, outcome.setup.tasks[0])
    return outcome, out, original, score


def _check(outcome, out, original, score, version):
    synx = outcome.setup.data.synx is not None
    ours = moment_rms(out, synx=synx)["gait_1"]
    theirs = moment_rms(original, synx=synx)["gait_1"]
    row = ComparisonRow(version, outcome.tasks[-1].cost, score.cost, ours, theirs,
                        parameters_within_bounds(outcome.state), outcome.wall_time, synx)
    print("\n" + comparison_table([row]))
    assert outcome.tasks[-1].cost <= score.cost
    assert row.worst_ratio <= 1.1
    assert row.within_bounds


@pytest.fixture(scope="module")
def v3(shared_data, tmp_path_factory):
    return _run(shared_data, tmp_path_factory, "V3")


def test_v3_against_the_original(v3):
    _check(*v3, "V3")


def test_v3_outputs(v3):
    outcome, out, _, _ = v3
    osimx = read_osimx(out / "UF_Subject_3_reduced_muscles_mtp.osimx")
    muscles = outcome.final_muscles
    for i, name in enumerate(muscles.names):
        entry = osimx.muscles[name]
        # raw MTP units: delay 0.1 s in [0, 1.25], time constant 0.01 s in [0.75, 3.5]
        assert 0.0 <= entry.electromechanical_delay <= 1.25
        assert 0.75 <= entry.activation_time_constant <= 3.5
        assert entry.optimal_fiber_length == pytest.approx(muscles.optimal_fiber_length[i], rel=1e-12)
        assert entry.tendon_slack_length == pytest.approx(muscles.tendon_slack_length[i], rel=1e-12)
        assert entry.max_isometric_force == pytest.approx(muscles.max_isometric_force[i], rel=1e-12)  # MTLI on
    for quantity in ("muscleExcitations", "muscleActivations", "normalizedFiberLengths", "modelJointMoments",
                     "inverseDynamicsJointMoments", "passiveForcesModel", "totalMuscleForces", "activeMuscleForces",
                     "passiveMuscleForces", "tendonForces"):
        table = read_storage(out / "Analysis" / quantity / f"gait_1_{quantity}.sto")
        assert table.n_rows == 101 and np.all(np.isfinite(table.data))
        assert table.time[0] == pytest.approx(0.5) and table.time[-1] == pytest.approx(1.6)
    assert not (out / "Analysis" / "muscleActivationsSynx").exists()
    assert len(list((out / "Analysis" / "passiveJointMomentsModeled").glob("*.sto"))) == 12
    params = read_storage(out / "Analysis" / "muscleModelParameters" / "muscleModelParameters.sto")
    assert params.n_rows == 6 and params.labels == muscles.names
    assert read_storage(out / "muscleActivations" / "gait_1_muscleActivations.sto").labels == muscles.names
    assert read_storage(out / "modelMoments" / "gait_1_modelMoments.sto").labels == outcome.data.coordinates
    assert (out / "MTPSettingsV3.xml").is_file()
    assert not list(out.glob(".staging-*"))


def test_v3_plots(v3, tmp_path):
    _, out, _, _ = v3
    assert is_mtp_results(out)
    written = plot_mtp_results(out, tmp_path)
    assert {p.name for p in written} == {"mtp_gait_1_moments.png", "mtp_gait_1_activations.png",
                                         "mtp_gait_1_fiber_lengths.png", "mtp_passive_moments.png",
                                         "mtp_parameters.png", "convergence.png"}
    assert all(p.stat().st_size > 10_000 for p in written)


def test_v3_convergence_table(v3):
    """MTLI's and each task's IPOPT iterates (start included) in ``convergence.tsv``."""
    outcome, out, _, _ = v3
    histories = read_convergence_table(out / "convergence.tsv")
    assert list(histories) == ["mtli"] + [f"task_{t.index}" for t in outcome.tasks]
    for task in outcome.tasks:
        history = histories[f"task_{task.index}"]
        assert history.n_iterations == task.iterations + 1
        assert history.cost[-1] == pytest.approx(task.cost, rel=1e-6)
        assert history.violation is not None and history.violation[-1] <= 1e-6


@pytest.mark.parametrize("version", ["V1", "V2"])
def test_synx_versions_against_the_original(shared_data, tmp_path_factory, version):
    outcome, out, original, score = _run(shared_data, tmp_path_factory, version)
    _check(outcome, out, original, score, version)
    assert (out / "Analysis" / "muscleActivationsSynx" / "gait_1_muscleActivationsSynx.sto").is_file()

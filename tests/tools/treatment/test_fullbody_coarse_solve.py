"""The full-body gait stress case's TO solved from its settings file on the coarse mesh
(issue 24): 31 state coordinates, 86 synergy-driven muscles, 212 contact springs on two feet,
5 x 4 collocation points, the case's limited-memory Hessian. IPOPT succeeds and the results
hold the states, controls, synergy commands, activations and both feet's ground reactions.
Every tracking term within its ``max_allowable_error`` is not reached yet (docs/treatment.md,
"Full-body gait case"): that check is a strict expected failure. Slow: several CPU minutes.
"""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="module")
def coarse_run(shared_data, tmp_path_factory):
    from nmsm.examples.fullbody import write_case
    from nmsm.tools.treatment.run import run_settings

    settings = write_case(tmp_path_factory.mktemp("fullbody_coarse"), "stress", "coarse", shared_data, quick=True)
    return run_settings(settings["to"])


@pytest.mark.slow
def test_stress_tracking_optimization_coarse_mesh_converges(coarse_run) -> None:
    assert coarse_run.solution.success, coarse_run.solution.status
    folder = Path(coarse_run.results_directory)
    written = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
    for name in ("gait_1_states.sto", "gait_1_torqueControls.sto", "gait_1_synergyCommands.sto",
                 "gait_1_combinedActivations.sto", "GRFData/gait_1.sto"):
        assert name in written, sorted(written)


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="on the coarse mesh the right ankle and both subtalar angles track "
                                       "at 6-7 deg RMS, above their 5 deg max_allowable_error")
def test_stress_tracking_within_max_allowable_error(coarse_run) -> None:
    from nmsm.examples.fullbody_checks import tracking_errors

    misses = {label: v for label, v in tracking_errors(coarse_run).items() if v[0] > v[1]}
    assert not misses, misses

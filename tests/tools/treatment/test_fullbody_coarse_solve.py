"""The full-body gait stress case's TO solved from its settings file on the coarse mesh
(issue 24): 31 state coordinates, 86 synergy-driven muscles, 212 contact springs on two feet,
5 x 4 collocation points, the case's limited-memory Hessian. IPOPT succeeds and the results
hold the states, controls, synergy commands, activations and both feet's ground reactions.
The VO started from those results reproduces them. Every tracking term within its ``max_allowable_error`` is not reached yet (docs/treatment.md,
"Full-body gait case"): that check is a strict expected failure. Slow: several CPU minutes.
"""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="module")
def coarse_chain(shared_data, tmp_path_factory):
    from nmsm.examples.fullbody import write_case
    from nmsm.tools.treatment.run import run_settings

    settings = write_case(tmp_path_factory.mktemp("fullbody_coarse"), "stress", "coarse", shared_data, quick=True)
    return settings, run_settings(settings["to"])


@pytest.fixture(scope="module")
def coarse_run(coarse_chain):
    return coarse_chain[1]


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


@pytest.mark.slow
def test_verification_from_the_tracking_results_reproduces_them(coarse_chain) -> None:
    """The TO's own speeds and accelerations lie outside the bounds the VO derives from the
    splined positions the TO wrote, and its speed at the first (not collocated) point is not
    their derivative: the VO's bounds cover the TO's solution and its settings pin only the
    initial positions, so it starts feasible and at its optimum."""
    from nmsm.examples.fullbody_checks import vo_versus_to
    from nmsm.tools.treatment.run import run_settings

    settings, to_run = coarse_chain
    vo = run_settings(settings["vo"])
    assert vo.solution.success and vo.solution.iterations <= 3, (vo.solution.status, vo.solution.iterations)
    change = vo_versus_to(vo, Path(to_run.results_directory))
    assert change["max_angle_deg"] <= 0.1 and change["max_moment_Nm"] <= 0.1, change

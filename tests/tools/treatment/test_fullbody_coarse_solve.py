"""The full-body gait stress case's TO solved from its settings file on the coarse mesh
(issue 24): 31 state coordinates, 86 synergy-driven muscles, 212 contact springs on two feet,
5 x 4 collocation points, the case's limited-memory Hessian. IPOPT succeeds, every tracking
term's RMS is within its ``max_allowable_error``, and the results hold the states, controls,
synergy commands, activations and both feet's ground reactions. Slow: several CPU minutes.
"""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.slow
def test_stress_tracking_optimization_coarse_mesh(shared_data, tmp_path) -> None:
    from nmsm.examples.fullbody import write_case
    from nmsm.examples.fullbody_checks import tracking_errors
    from nmsm.tools.treatment.run import run_settings

    settings = write_case(tmp_path / "case", "stress", "coarse", shared_data, quick=True)
    run = run_settings(settings["to"])
    assert run.solution.success, run.solution.status
    misses = {label: v for label, v in tracking_errors(run).items() if v[0] > v[1]}
    assert not misses, misses
    folder = Path(run.results_directory)
    written = {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}
    for name in ("gait_1_states.sto", "gait_1_torqueControls.sto", "gait_1_synergyCommands.sto",
                 "gait_1_combinedActivations.sto", "GRFData/gait_1.sto"):
        assert name in written, sorted(written)

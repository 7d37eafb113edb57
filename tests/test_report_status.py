"""The report's status rows, read from the files tools write (nmsm.report.status)."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.io.storage import table_from_columns, write_storage
from nmsm.report.status import is_converged, solver_outcomes, stage_status
from nmsm.report.tables import gcp_errors


@pytest.mark.parametrize(("status", "converged"), [
    ("Solve_Succeeded", True), ("Solved_To_Acceptable_Level", True), ("nothing to optimize", True),
    ("`ftol` termination condition is satisfied.", True),
    ("Both `ftol` and `xtol` termination conditions are satisfied.", True),
    ("Maximum_Iterations_Exceeded", False), ("Restoration_Failed", False), ("Infeasible_Problem_Detected", False),
    ("The maximum number of function evaluations is exceeded.", False), ("unknown", False)])
def test_converged_statuses(status: str, converged: bool) -> None:
    assert is_converged(status) is converged


def test_solver_outcomes_of_every_summary_shape() -> None:
    text = ("task 1 (3.0 s): ipopt: Solve_Succeeded after 12 iterations, 2.50 s, cost 1.5\n"
            "task 2: Maximum_Iterations_Exceeded; cost 0.5; 300 iterations; 4.25 s\n"
            "walk: IPOPT Solved_To_Acceptable_Level after 7 iterations, 1.00 s; objective 3\n"
            "task 3 (9.0 s): least_squares (lifted foot coordinates): The maximum number of function evaluations is "
            "exceeded. after 60 iterations, 8.50 s, cost 0.6\n")
    found = solver_outcomes(text)
    assert [(o.status, o.iterations, o.seconds, o.converged) for o in found] == [
        ("Solve_Succeeded", 12, 2.5, True), ("Maximum_Iterations_Exceeded", 300, 4.25, False),
        ("Solved_To_Acceptable_Level", 7, 1.0, True),
        ("The maximum number of function evaluations is exceeded.", 60, 8.5, False)]


def _treatment_folder(folder: Path, status: str, violated: int = 0) -> None:
    folder.mkdir(parents=True)
    (folder / "walk_convergence.txt").write_text(
        f"to: IPOPT {status} after 40 iterations, 12.50 s; objective 0.1\n\ncost terms:\n\n"
        + (f"{violated} constraint block(s) violated by more than 1e-4\n" if violated else
           "all constraints satisfied within 1e-4\n"), encoding="utf-8")
    analysis = folder / "Analysis"
    analysis.mkdir()
    t = [0.0, 0.5, 1.0]
    write_storage(analysis / "walk_modeledPositions.sto", table_from_columns(t, {"knee": [0.0, 0.1, 0.2],
                                                                                 "pelvis_tx": [0, 0, 0.003]}))
    write_storage(analysis / "walk_trackedPositions.sto", table_from_columns(t, {"knee": [0.0, 0.1, 0.2 + 0.03],
                                                                                 "pelvis_tx": [0, 0, 0]}))


def test_treatment_status(tmp_path: Path) -> None:
    _treatment_folder(tmp_path / "ok", "Solve_Succeeded")
    status = stage_status("treatment", tmp_path / "ok")
    assert status.converged is True and status.solver == "Solve_Succeeded" and status.seconds == 12.5
    assert status.headline == "tracking RMS ≤ 0.992 deg (knee), ≤ 1.73 mm (pelvis_tx)", status.headline
    # an unconverged solve's last iterate, in a sub-folder, is reported as not converged
    _treatment_folder(tmp_path / "bad" / "last_iterate", "Maximum_Iterations_Exceeded", violated=2)
    status = stage_status("treatment", tmp_path / "bad")
    assert status.converged is False and "2 constraint block(s) violated" in status.headline


def test_gcp_errors_of_two_feet(tmp_path: Path) -> None:
    from nmsm.tools.gcp.report import ROWS, format_error_table

    values = {"foot 1": {row: 1.0 + k for k, row in enumerate(ROWS)}, "foot 2": {row: 20.0 + k for k, row in
                                                                              enumerate(ROWS)}}
    (tmp_path / "leg_gcpErrors.txt").write_text(format_error_table(values), encoding="utf-8")
    assert gcp_errors(tmp_path) == values
    (tmp_path / "commandWindowOutput.txt").write_text(
        "task 1 (2.0 s): ipopt: Solve_Succeeded after 5 iterations, 1.50 s, cost 1\n", encoding="utf-8")
    status = stage_status("gcp", tmp_path)
    assert status.converged is True
    assert status.headline == ("foot 1: force RMS ≤ 3 N, moment RMS ≤ 6 N·m; "
                               "foot 2: force RMS ≤ 22 N, moment RMS ≤ 25 N·m")


def test_a_folder_without_summaries_is_unknown(tmp_path: Path) -> None:
    for kind in ("jmp", "mtp", "ncp", "gcp", "treatment", "analysis", "batch"):
        assert stage_status(kind, tmp_path).converged is None

"""Ctrl-C during a treatment solve: nothing is left behind, not even an empty results folder."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from nmsm.core.problem import OptimizationProblem
from nmsm.tools.treatment.run import run_settings

SETTINGS = "treatment/torque_kick_tutorial/CompletedSettingsFiles/TorqueTOSettingsV1.xml"


def _stopped(*args: object, **kwargs: object) -> None:
    raise KeyboardInterrupt("stopped by SIGINT during the solve")  # as interrupt_after_solve raises it


def test_a_stop_during_the_solve_leaves_no_results_folder(shared_data: Path, tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(OptimizationProblem, "solve", _stopped)
    results = tmp_path / "new" / "results"
    with warnings.catch_warnings(), pytest.raises(KeyboardInterrupt):
        warnings.simplefilter("ignore")
        run_settings(shared_data / SETTINGS, results_directory=results, print_level=0)
    assert not (tmp_path / "new").exists()


def test_a_stop_keeps_an_existing_results_folder_and_its_files(shared_data: Path, tmp_path: Path,
                                                              monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(OptimizationProblem, "solve", _stopped)
    results = tmp_path / "results"
    results.mkdir()
    (results / "notes.txt").write_text("mine", encoding="utf-8")
    with warnings.catch_warnings(), pytest.raises(KeyboardInterrupt):
        warnings.simplefilter("ignore")
        run_settings(shared_data / SETTINGS, results_directory=results, print_level=0)
    assert sorted(p.name for p in results.iterdir()) == ["notes.txt"]

"""The per-point model functions on two threads (``parallel``, default
``DEFAULT_PARALLEL``) give the one-thread solution."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from nmsm.tools.treatment.run import run_settings


def _run(settings: Path, results: Path, parallel: int):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_settings(settings, results_directory=results, print_level=0, parallel=parallel)


def test_two_threads_give_the_one_thread_solution(shared_data: Path, tmp_path: Path) -> None:
    settings = shared_data / "treatment" / "torque_kick_tutorial" / "CompletedSettingsFiles" / "TorqueTOSettingsV1.xml"
    one = _run(settings, tmp_path / "one", 1).solution
    two = _run(settings, tmp_path / "two", 2).solution
    assert one.success and two.success
    assert one.iterations == two.iterations
    np.testing.assert_allclose(two.x_scaled, one.x_scaled, rtol=0, atol=1e-12)


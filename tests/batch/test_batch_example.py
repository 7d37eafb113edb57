"""``nmsm example --batch`` (slow): the synthetic subject's pipeline up to the VO and the DO swept
over 5 weakness levels x 2 synergy scalings on a 2-worker LocalCluster; then a rerun that
skips every run; the report's batch section."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from batch_helpers import leftover_processes  # noqa: E402

from nmsm.batch import run  # noqa: E402
from nmsm.batch.summary import read_summary  # noqa: E402
from nmsm.examples.batch_example import STRENGTHS, SYNERGY_SCALES, run_example_batch  # noqa: E402


@pytest.mark.slow
def test_example_sweep_completes_and_a_rerun_skips_it(tmp_path, time_limit) -> None:
    time_limit(1500)
    first = run_example_batch(tmp_path / "example", workers=2, log=None)
    assert first.ok and first.count("ok") == 1 + len(STRENGTHS) * len(SYNERGY_SCALES), first.text()
    assert not leftover_processes()
    _, rows = read_summary(first.summary_file)
    sweep = [r for r in rows if r["sweep"] == "do"]
    assert len(sweep) == 10 and all(r["ipopt_status"] == "Solve_Succeeded" for r in sweep)
    for scale in SYNERGY_SCALES:
        # the weaker the plantarflexors, the further the predicted gait moves from the VO's
        change = [float(r["tracking_rms_deg"]) for r in sorted(
            (r for r in sweep if float(r["synergy_scale"]) == scale), key=lambda r: float(r["strength"]))]
        assert change == sorted(change, reverse=True) and change[0] > 2 * change[-1], (scale, change)
    assert (first.spec.results_directory / "plots" / "sweep_do.png").is_file()
    page = (first.spec.results_directory / "report.html").read_text(encoding="utf-8")
    assert "<h2>Batch</h2>" in page and "sweep_do.png" in page

    events: list = []
    second = run(first.spec.file, log=None, on_event=lambda kind, name, details: events.append(kind))
    assert {o.status for o in second.outcomes.values()} == {"skipped"}, second.text()
    assert "started" not in events and second.workers == 0

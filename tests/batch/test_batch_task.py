"""One run outside Dask (:func:`nmsm.batch.task.run_one`): a rerun that fails puts the earlier
results back, a first run that fails leaves a record, and the next batch accepts both folders;
an interrupted attempt is undone."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import attrs

sys.path.insert(0, str(Path(__file__).parent))

from batch_helpers import write_batch  # noqa: E402

from nmsm.batch.batch_file import read_batch  # noqa: E402
from nmsm.batch.execute import _check_folders, _finished_earlier  # noqa: E402
from nmsm.batch.graph import link  # noqa: E402
from nmsm.batch.sweep import expand  # noqa: E402
from nmsm.batch.task import admin_path, recover, run_one  # noqa: E402
from nmsm.tools.pipeline.hashing import DigestCache  # noqa: E402


def test_a_failed_rerun_puts_the_earlier_results_back(jmp_case, tmp_path) -> None:
    batch = write_batch(tmp_path, f'<Run name="a"><settings_file>{jmp_case.settings_file}</settings_file></Run>')
    spec = read_batch(batch)
    plan = link(spec, expand(spec))[0]
    first = run_one(plan, "digest-1")
    assert first.status == "ok" and first.objective is not None
    model = plan.folder / "personalized.osim"
    before = model.read_bytes()
    assert _finished_earlier(plan, "digest-1", DigestCache()) is not None

    failing = attrs.evolve(plan, overrides=(("JMPTaskList/JMPTask/marker_file_name", "missing.trc"),))
    second = run_one(failing, "digest-2")
    assert second.status == "failed" and "missing.trc" in second.message, second.message
    assert model.read_bytes() == before  # the earlier results are back, with their record
    assert "missing.trc" in plan.settings_copy.read_text(encoding="utf-8")  # what the message names
    assert not admin_path(plan, ".earlier").exists() and not admin_path(plan, ".attempt.json").exists()
    assert _finished_earlier(plan, "digest-1", DigestCache()) is not None
    assert _finished_earlier(plan, "digest-2", DigestCache()) is None
    _check_folders(spec, [plan])  # the batch's own folder: accepted

    other = attrs.evolve(failing, name="b", folder=tmp_path / "out" / "b", settings_copy=tmp_path / "out" / "b.xml")
    third = run_one(other, "digest-3")  # fails with nothing earlier: no folder, a record of the failure
    assert third.status == "failed" and not other.folder.exists()
    record = json.loads(admin_path(other, ".json").read_text(encoding="utf-8"))
    assert record["outcome"]["status"] == "failed" and record["input_digest"] is None
    assert _finished_earlier(other, "digest-3", DigestCache()) is None  # a failed run is never skipped
    _check_folders(spec, [other])


def test_an_interrupted_attempt_is_undone(jmp_case, tmp_path) -> None:
    batch = write_batch(tmp_path, f'<Run name="a"><settings_file>{jmp_case.settings_file}</settings_file></Run>')
    spec = read_batch(batch)
    plan = link(spec, expand(spec))[0]
    earlier = admin_path(plan, ".earlier")
    (earlier / "results").mkdir(parents=True)
    (earlier / "results" / "result.txt").write_text("earlier", encoding="utf-8")
    (earlier / "settings.xml").write_text("earlier settings", encoding="utf-8")
    (earlier / "record.json").write_text("{}", encoding="utf-8")
    plan.folder.mkdir(parents=True)
    (plan.folder / "half.txt").write_text("half", encoding="utf-8")
    plan.settings_copy.write_text("this attempt's settings", encoding="utf-8")
    admin_path(plan, ".attempt.json").write_text("{}", encoding="utf-8")
    assert recover(plan)
    assert sorted(p.name for p in plan.folder.iterdir()) == ["result.txt"]
    assert plan.settings_copy.read_text(encoding="utf-8") == "earlier settings"
    assert admin_path(plan, ".json").read_text(encoding="utf-8") == "{}"
    assert not earlier.exists() and not admin_path(plan, ".attempt.json").exists()
    assert not recover(plan)

    admin_path(plan, ".attempt.json").write_text("{}", encoding="utf-8")  # a first attempt, killed
    admin_path(plan, ".json").unlink()
    assert recover(plan)
    assert not plan.folder.exists() and not plan.settings_copy.exists()

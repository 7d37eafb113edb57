"""The shared JMP settings files run as they are: tutorial (sequential, simultaneous), Rajagopal
isolated knee, gait2392 (2023 schema). Errors compared with the original tool's output models,
both evaluated with our inverse kinematics."""

from __future__ import annotations

import itertools
import json
import warnings

import numpy as np
import pytest

from nmsm.io.storage import read_storage
from nmsm.model import load_model
from nmsm.plots.jmp import is_jmp_results, plot_jmp_results
from nmsm.tools.jmp.ik import inverse_kinematics
from nmsm.tools.jmp.run import RESULTS_FILE, run_settings

TUTORIAL = "jmp/uf_subject3_tutorial/CompletedSettingsFiles"


def _run(path, out):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # Windows paths found relative to the step folder, old schemas
        return run_settings(path, results_directory=out, quiet=True)


def _task_rms(model_file, task) -> float:
    result = inverse_kinematics(model_file, task.trial, accuracy=1e-6, check_marker_units=False)
    return result.marker_rms()


def _frame_angles(model, joint: str, which: str) -> np.ndarray:
    j = model.joint(joint)
    return model.frames[j.parent_frame if which == "parent" else j.child_frame].orientation


@pytest.mark.slow
@pytest.mark.parametrize("name", ["Sequential", "Simultaneous"])
def test_tutorial_beats_the_original_output(shared_data, tmp_path, name):
    folder = shared_data / TUTORIAL
    run = _run(folder / f"JMPSettings{name}.xml", tmp_path)
    original = folder / f"UF_Subject_3_Scaled_{name}.osim"
    ours, theirs = load_model(run.output_model), load_model(original)
    print(f"\n{name}: marker RMS (mm) per task trial, ours vs the original's output (our IK)")
    for task in run.tasks:
        ours_rms, theirs_rms = _task_rms(run.output_model, task), _task_rms(original, task)
        print(f"  {task.label}: {1000 * ours_rms:.4f} vs {1000 * theirs_rms:.4f}")
        assert ours_rms <= theirs_rms
    print("  parameter differences, ours - original:")
    for joint, which in (("knee_r", "parent"), ("knee_r", "child"), ("ankle_r", "parent"), ("subtalar_r", "parent"),
                         ("subtalar_r", "child")):
        delta = np.degrees(_frame_angles(ours, joint, which) - _frame_angles(theirs, joint, which))
        print(f"    {joint} {which} orientation (deg): {np.round(delta, 3)}")
        if joint == "knee_r":  # well determined; ankle/subtalar are not (flat valleys), only reported
            assert np.all(np.abs(delta) <= 3.0)
    hip = "/jointset/hip_r/pelvis_offset"
    base = load_model(folder / "UF_Subject_3_Scaled.osim").frames[hip].translation
    scale_ours, scale_theirs = (m.frames[hip].translation[2] / base[2] for m in (ours, theirs))
    print(f"    pelvis scale: {scale_ours:.5f} vs {scale_theirs:.5f}")
    assert scale_ours == pytest.approx(scale_theirs, rel=0.01)
    assert is_jmp_results(tmp_path)
    figures = plot_jmp_results(tmp_path)
    assert [f.name for f in figures].count("convergence.png") == 1
    assert len(figures) == len(run.tasks) + 2  # one per task, the summary, the convergence


def _label_permutation(start, before) -> dict[str, str]:
    """The expected files' column labels do not name the columns' markers: find which of our
    markers each column holds by matching the 'start' errors (input model) with ours."""
    rms = {label: float(np.sqrt(np.mean(start.column(label) ** 2))) for label in start.labels}
    ours = {name: float(np.sqrt(np.nanmean(before[:, k] ** 2))) for k, name in enumerate(start.labels)}
    best, best_cost = None, np.inf
    for perm in itertools.permutations(start.labels):
        cost = sum((rms[label] - ours[marker]) ** 2 for label, marker in zip(start.labels, perm))
        if cost < best_cost:
            best, best_cost = dict(zip(start.labels, perm)), cost
    return best


@pytest.mark.slow
def test_rajagopal_isolated_knee_per_marker_errors_below_expected(shared_data, tmp_path):
    folder = shared_data / "jmp/rajagopal_isolated_knee"
    run = _run(folder / "IsolatedReinboltKneeExample.xml", tmp_path)
    start = read_storage(folder / "expected/start.sto")
    finish = read_storage(folder / "expected/finish.sto")
    markers = list(start.labels)
    # the original reported errors with IK on these 6 markers only: do the same
    weights = {m: 1.0 for m in markers}
    before = inverse_kinematics(folder / "Rajagopal_4.0_RCNL_markers_scaled.osim", folder / "l_knee.trc",
                                weights=weights, accuracy=1e-6).marker_errors
    after = inverse_kinematics(run.output_model, folder / "l_knee.trc", weights=weights, accuracy=1e-6).marker_errors
    mapping = _label_permutation(start, before)
    assert max(abs(np.sqrt(np.mean(start.column(label) ** 2)) - np.sqrt(np.nanmean(before[:, markers.index(m)] ** 2)))
               for label, m in mapping.items()) < 5e-5  # start.sto reproduced to 0.05 mm
    print("\nper-marker RMS / max (mm): ours after vs expected/finish.sto")
    for label, marker in mapping.items():
        ours = after[:, markers.index(marker)]
        expected = finish.column(label)
        print(f"  {marker:18s} {1000 * np.sqrt(np.mean(ours**2)):7.3f} vs {1000 * np.sqrt(np.mean(expected**2)):7.3f}"
              f"   {1000 * ours.max():7.3f} vs {1000 * expected.max():7.3f}")
        assert np.sqrt(np.mean(ours**2)) <= np.sqrt(np.mean(expected**2))
        assert ours.max() <= expected.max()


def test_gait2392_old_schema_runs(shared_data, tmp_path):
    folder = shared_data / "jmp/gait2392_walk_free"
    run = _run(folder / "JMPSettings.xml", tmp_path)
    task = run.tasks[0]
    assert [v.label for v in task.design.variables] == [f"hip_l parent translation {a}" for a in "xyz"]
    assert task.trial.n_markers == 31  # the applied markers of the IK settings the old schema named
    assert task.after.marker_rms() < task.before.marker_rms()
    bounds = np.abs(task.values - task.design.initial)
    assert np.all(bounds <= 0.005 + 1e-12)  # translation_bounds honoured
    original_rms = _task_rms(folder / "subject01_gait2392_scaled_output.osim", task)
    assert task.after.marker_rms() <= original_rms
    summary = json.loads((tmp_path / RESULTS_FILE).read_text())
    assert summary["tasks"][0]["errors"][0]["group"] == "all markers"

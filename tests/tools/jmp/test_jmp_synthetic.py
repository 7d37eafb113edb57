"""Known-answer JMP cases generated in code (perturbed knee and ankle axes, noisy markers)."""

from __future__ import annotations


import numpy as np
import pytest

from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case, recovery_errors, run_example
from nmsm.io.trc import read_trc
from nmsm.model import load_model
from nmsm.terms.jmp.marker_distance import MarkerDistanceError
from nmsm.tools.jmp.design import build_design
from nmsm.tools.jmp.ik import inverse_kinematics
from nmsm.core.backends.levenberg_marquardt import Tolerances
from nmsm.tools.jmp.marker_data import select_trial
from nmsm.tools.jmp.marker_model import MarkerKinematics
from nmsm.tools.jmp.problem import JmpProblem
from nmsm.tools.jmp.run import read_settings, run_settings

#: recovery tolerance with 0.5 mm marker noise, 201 frames (measured errors are <= 0.06 deg)
NOISY_TOLERANCE_DEG = 0.15


def test_leg_without_noise_is_recovered_exactly(tmp_path):
    case, run, errors = run_example(tmp_path, noise=0.0)
    assert len(errors) == 6
    assert max(abs(np.degrees(e)) for e in errors.values()) <= 1e-6
    assert run.tasks[0].after.marker_rms() <= 1e-8
    # the nominal model really was off: 3-5 deg per parameter
    assert min(abs(v.initial - case.truth[v.label]) for v in run.tasks[0].design.variables) >= np.radians(2.9)


def test_leg_with_noise_is_recovered_within_tolerance(tmp_path):
    case, run, errors = run_example(tmp_path, noise=0.0005)
    assert max(abs(np.degrees(e)) for e in errors.values()) <= NOISY_TOLERANCE_DEG
    task = run.tasks[0]
    assert task.before.marker_rms() > 5e-3  # 6 mm before
    assert task.after.marker_rms() < 1e-3  # the noise level (0.5 mm per axis) after


def test_rcnl_model_with_noise_is_recovered_within_tolerance(shared_data, tmp_path):
    model = shared_data / "jmp/uf_subject3_tutorial/CompletedSettingsFiles/UF_Subject_3_Scaled.osim"
    case = make_synthetic_jmp_case(tmp_path, model_file=model, noise=0.0005)
    run = run_settings(case.settings_file, quiet=True)
    errors = recovery_errors(case, run)
    assert set(errors) == {f"{j} {w} orientation {a}" for j, w, a in
                           (("knee_r", "parent", "x"), ("knee_r", "parent", "y"), ("knee_r", "child", "x"),
                            ("knee_r", "child", "y"), ("ankle_r", "parent", "x"), ("ankle_r", "parent", "y"))}
    assert max(abs(np.degrees(e)) for e in errors.values()) <= NOISY_TOLERANCE_DEG


def test_small_range_of_motion_warns(tmp_path):
    case = make_synthetic_jmp_case(tmp_path, noise=0.0005, motion_scale=0.2)
    with pytest.warns(UserWarning, match="joint 'knee' moves little"):
        run_settings(case.settings_file, quiet=True)


def test_generic_least_squares_back_end_agrees(tmp_path):
    """The same task as an OptimizationProblem solved by scipy, and by Levenberg-Marquardt on its
    sparse Jacobian, through the generic back ends."""
    case = make_synthetic_jmp_case(tmp_path, noise=0.0005, duration=0.4)
    settings = read_settings(case.settings_file)
    task = settings.tasks[0]
    model = load_model(settings.input_model_file)
    table = read_trc(task.marker_file_name)
    design = build_design(model, task, table.names)
    trial = select_trial(table, model, {m: 1.0 for m in design.marker_names})
    kin = MarkerKinematics(model, trial.names, design.parameters)
    before = inverse_kinematics(model, trial, kinematics=kin, parameters=design.parameters)
    q0 = before.q[:, [before.coordinate_names.index(n) for n in kin.free_names]]
    problem = JmpProblem(kin, trial, [MarkerDistanceError(max_allowable_error=0.01)], design.lower, design.upper)
    ours = problem.solve(q0, design.initial, Tolerances(xtol=1e-12, ftol=1e-14, gtol=1e-12))
    stated = problem.optimization_problem(q0, design.initial)
    generic = stated.solve("least_squares", xtol=1e-12, ftol=1e-14, gtol=1e-12)
    assert generic.cost == pytest.approx(ours.cost, rel=1e-8)
    np.testing.assert_allclose(generic["p"].ravel(), ours.p, atol=1e-7)
    sparse = stated.solve("levenberg_marquardt", xtol=1e-12, ftol=1e-14, gtol=1e-12)
    assert sparse.backend == "levenberg_marquardt" and sparse.success
    assert sparse.cost == pytest.approx(ours.cost, rel=1e-8)
    np.testing.assert_allclose(sparse["p"].ravel(), ours.p, atol=1e-7)
    assert ours.term_costs["marker_distance_error"] == pytest.approx(ours.cost, rel=1e-12)


def test_mm_marker_file_labelled_m_is_handled(tmp_path):
    case = make_synthetic_jmp_case(tmp_path, noise=0.0)
    text = case.marker_file.read_text()
    header = text.splitlines()[2].split("\t")
    assert header[4] == "mm"
    lines = text.splitlines()
    header[4] = "m"
    lines[2] = "\t".join(header)
    case.marker_file.write_text("\n".join(lines) + "\n")
    with pytest.warns(UserWarning, match="look like mm"):
        run = run_settings(case.settings_file, quiet=True)
    assert max(abs(e) for e in recovery_errors(case, run).values()) <= 1e-6

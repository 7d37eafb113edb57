"""Known answer: ground reactions generated in code from known springs, properties and
kinematics (nmsm.examples.synthetic_gcp) are recovered by ``run_settings``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from nmsm.core.convergence import read_convergence_table
from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage
from nmsm.tools.gcp.filtering import lowpass
from nmsm.tools.gcp.run import run_settings


@pytest.fixture(scope="module")
def synthetic_run(synthetic_case, tmp_path_factory):
    out = tmp_path_factory.mktemp("synthetic_results")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # the case stops at its 60 residual evaluations, as the example does
        result = run_settings(synthetic_case.settings_file, results_directory=out, accept_unconverged=True)
    return synthetic_case, result


def test_properties_recovered(synthetic_run):
    case, result = synthetic_run
    state = result.groups[0].state
    truth = case.truth
    assert state.resting_spring_length == pytest.approx(truth.resting_spring_length, abs=2e-5)
    assert state.damping_factor == pytest.approx(truth.damping_factor, rel=0.02)
    assert state.dynamic_friction_coefficient == pytest.approx(truth.dynamic_friction_coefficient, rel=0.02)
    assert state.viscous_friction_coefficient == pytest.approx(truth.viscous_friction_coefficient, abs=0.01)
    relative = np.abs(state.spring_constants / case.spring_constants - 1)
    assert np.median(relative) < 0.01 and relative.max() < 0.05


def test_reactions_and_kinematics_reproduced(synthetic_run):
    _, result = synthetic_run
    errors = result.errors[1]
    for row in ("Fx (N)", "Fy (N)", "Fz (N)"):
        assert errors[row] < 0.05
    for row in ("Mx (N m)", "My (N m)", "Mz (N m)"):
        assert errors[row] < 0.01
    assert errors["translation (mm)"] < 0.2 and errors["rotation (deg)"] < 0.05
    assert result.final_cost < 0.01


def test_result_files(synthetic_run):
    case, result = synthetic_run
    folder = result.results_directory
    names = {p.name for p in folder.iterdir()}
    for suffix in ("experimentalFootKinematics", "optimizedFootKinematics", "replacedExperimentalGroundReactions",
                   "optimizedGroundReactions"):
        assert f"foot_Foot_1_{suffix}.sto" in names
    assert {"foot_gcp.osimx", "foot_gcpErrors.txt", "settings.xml", "commandWindowOutput.txt",
            "convergence.tsv"} <= names
    histories = read_convergence_table(folder / "convergence.tsv")  # one per task, sum(r**2) per accepted iterate
    solutions = result.groups[0].solutions
    assert list(histories) == [f"task_{k}" for k in range(1, len(solutions) + 1)]
    for history, solution in zip(histories.values(), solutions):
        assert history.violation is None and np.all(np.isfinite(history.optimality))
        assert history.cost[0] >= history.cost[-1] >= 0
    assert not [n for n in names if n.startswith(".staging")]
    surface = read_osimx(folder / "foot_gcp.osimx").contact_surfaces[0]
    assert len(surface.springs) == case.spring_constants.size
    assert surface.hindfoot_body == "calcn_r" and surface.belt_speed == pytest.approx(1.2)
    modeled = read_storage(folder / "GRFData" / "gcp_modeled_grf.sto")
    assert modeled.labels == ("f1_vx", "f1_vy", "f1_vz", "f1_px", "f1_py", "f1_pz", "m1_x", "m1_y", "m1_z")
    cop = read_storage(folder / "GRFData" / "gcp_modeled_grf_CoP.sto")
    assert np.allclose(cop.column("m1_x"), 0) and np.allclose(cop.column("m1_z"), 0)
    motion = read_storage(folder / "IKData" / "gcp_modeled_ik.sto")
    original = read_storage(case.motion_file)
    assert motion.in_degrees
    # the re-solved motion follows the (nearly exact) modeled foot: the same 4th-order 6 Hz
    # low-pass of the input motion, within a millimetre / 0.1 degree
    filtered = lowpass(original.time, original.columns(["foot_tx_r", "foot_ty_r", "foot_tz_r"]), 4, 6.0)
    np.testing.assert_allclose(motion.columns(["foot_tx_r", "foot_ty_r", "foot_tz_r"]), filtered, atol=1e-3)
    filtered = lowpass(original.time, np.degrees(original.column("foot_rotation_z_r")), 4, 6.0)
    np.testing.assert_allclose(motion.column("foot_rotation_z_r"), filtered, atol=0.1)


def test_plots(synthetic_run, tmp_path):
    from nmsm.plots.gcp import plot_gcp_results

    _, result = synthetic_run
    files = plot_gcp_results(result.results_directory, tmp_path)
    assert sorted(f.name for f in files) == ["Foot_1_forces.png", "Foot_1_kinematics.png", "Foot_1_moments.png",
                                             "Foot_1_stiffness.png", "convergence.png"]
    assert all(f.stat().st_size > 10_000 for f in files)

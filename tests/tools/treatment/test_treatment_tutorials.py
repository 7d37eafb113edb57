"""Tutorial settings files run as they are, compared with the original pipeline's results.

Criteria (issue 8): converged; our final cost <= the original's solution scored in our problem;
tracked-quantity RMS <= max(1.1 x the original's, 0.05 deg / 0.5 N·m); VO reproduces the TO
it starts from (<= 0.1 deg, <= 0.1 N·m) in far fewer iterations; a DO's objective within 10 %
of the original's, or IPOPT restarted from the original's solution finds nothing better than
ours (the original had not converged in our problem). ``benchmarks/bench_treatment.py`` prints
the full table (docs/developing.md, "Treatment: measurements and audit trail"). The toy arm and
the torque TO V1 -> VO V1 chain run by default; the other tutorials are ``slow``.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from nmsm.io.storage import read_storage
from nmsm.tools.treatment.compare import Comparison, legacy_solution_folder, score_solution
from nmsm.tools.treatment.outcome import TreatmentRun
from nmsm.tools.treatment.run import run_settings

#: known RMS exceedances at a lower total cost (a different trade-off between the terms), see
#: docs/developing.md (Treatment); any other exceedance fails
KNOWN_RMS_EXCEEDANCES = {
    "SynergyTOSettingsV3": {"generalized_speed_tracking:ankle_angle_r"},
    "SynergyTOSettingsV4": {"generalized_speed_tracking:ankle_angle_r", "muscle_activation_tracking:gasmed_r",
                            "muscle_activation_tracking:glmax2_r", "muscle_activation_tracking:vasmed_r"},
    "SynergyTOSettingsV5": {"generalized_speed_tracking:ankle_angle_r", "muscle_activation_tracking:glmax2_r",
                            "muscle_activation_tracking:vasmed_r"},
}


def _settings(shared: Path, name: str) -> Path:
    folder = "torque_kick_tutorial" if name.startswith("Torque") else "synergy_kick_tutorial"
    return shared / "treatment" / folder / "CompletedSettingsFiles" / f"{name}.xml"


def _original(path: Path) -> Path:
    return path.parent / path.stem.replace("Settings", "Results")


def _quiet(fn, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args, **kwargs)


def _check(comp: Comparison, known: set[str] = frozenset()) -> None:
    assert comp.ours.solution.success, comp.ours.summary
    assert comp.ours.cost <= comp.theirs.initial_cost * (1 + 1e-6), comp.report()
    assert set(comp.rms_failures()) <= set(known), comp.report()


def _run_and_compare(shared: Path, name: str, tmp_path: Path, **options) -> Comparison:
    path = _settings(shared, name)
    ours = _quiet(run_settings, path, results_directory=tmp_path / name, print_level=0, **options)
    theirs = _quiet(score_solution, path, _original(path), **options)
    return Comparison(ours, theirs)


def _vo_versus_to(vo: TreatmentRun, to_folder: Path) -> tuple[float, float]:
    """Max |Δq| (deg) and |Δτ| (N·m) over the state coordinates, VO vs the TO results folder."""
    trial = vo.prepared.settings.trial_name
    model = vo.prepared.model
    states = list(vo.prepared.data.state_coordinates)
    j = [model.coordinate_names.index(c) for c in states]
    t = vo.result.time
    ik = read_storage(to_folder / "IKData" / f"{trial}.sto")
    iddata = read_storage(to_folder / "IDData" / f"{trial}.sto")

    def at(table, labels):
        return np.column_stack([np.interp(t, table.time - table.time[0], table.column(c)) for c in labels])

    dq = np.degrees(np.max(np.abs(vo.result.positions[:, j] - at(ik, states))))
    dtau = np.max(np.abs(vo.result.inverse_dynamics[:-1, j] - at(iddata, [model.load_label(c) for c in states])[:-1]))
    return float(dq), float(dtau)


def test_torque_tracking_v1_then_verification(shared_data: Path, tmp_path: Path) -> None:
    comp = _run_and_compare(shared_data, "TorqueTOSettingsV1", tmp_path)
    _check(comp)
    out = tmp_path / "TorqueTOSettingsV1"
    for name in ("drive_kick1_states.sto", "drive_kick1_accelerations.sto", "drive_kick1_torqueControls.sto",
                 "IKData/drive_kick1.sto", "IDData/drive_kick1.sto", "drive_kick1_convergence.txt",
                 "TorqueTOSettingsV1.xml"):
        assert (out / name).is_file(), name
    assert read_storage(out / "IKData" / "drive_kick1.sto").n_rows == 101
    # VO V1 on our TO: reproduces it within 0.1 deg / 0.1 N·m in far fewer iterations
    vo = _quiet(run_settings, _settings(shared_data, "TorqueVOSettingsV1"), results_directory=tmp_path / "vo",
                initial_guess_directory=out, tracked_quantities_directory=out, print_level=0)
    assert vo.solution.success and vo.solution.iterations <= comp.ours.solution.iterations / 2
    dq, dtau = _vo_versus_to(vo, out)
    assert dq <= 0.1 and dtau <= 0.1, (dq, dtau)


# ---- toy arm (2023 schema 0.1.0, upgraded in memory) ------------------------------------------
TOY = {"tracking": "TorqueDrivenTOSettings.xml", "verification": "TorqueDrivenVOSettings.xml",
       "design": "TorqueDrivenDOSettings.xml"}


def _toy(shared: Path, tool: str) -> Path:
    return shared / "treatment" / "toy_arm" / f"{tool}_optimization" / TOY[tool]


@pytest.mark.parametrize("tool", list(TOY))
def test_toy_arm(shared_data: Path, tmp_path: Path, tool: str) -> None:
    path = _toy(shared_data, tool)
    ours = _quiet(run_settings, path, results_directory=tmp_path / "ours", print_level=0)
    original = legacy_solution_folder(path.parent / "statesSolution.sto", path.parent / "controlSolution.sto",
                                      tmp_path / "original", "arm1", ["r_elbow_flex"])
    theirs = _quiet(score_solution, path, original)
    _check(Comparison(ours, theirs))
    assert read_storage(tmp_path / "ours" / "arm1_states.sto").n_rows == 51


def test_toy_arm_verification_reproduces_tracking(shared_data: Path, tmp_path: Path) -> None:
    to = _quiet(run_settings, _toy(shared_data, "tracking"), results_directory=tmp_path / "to", print_level=0)
    vo = _quiet(run_settings, _toy(shared_data, "verification"), results_directory=tmp_path / "vo", print_level=0,
                initial_guess_directory=tmp_path / "to", tracked_quantities_directory=tmp_path / "to")
    assert vo.solution.success and vo.solution.iterations <= to.solution.iterations / 2
    dq, dtau = _vo_versus_to(vo, tmp_path / "to")
    assert dq <= 0.1 and dtau <= 0.1, (dq, dtau)


# ---- kicking tutorials (slow) ------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("name", ["TorqueTOSettingsV2", "SynergyTOSettingsV1", "SynergyTOSettingsV2",
                                  "SynergyTOSettingsV3", "SynergyTOSettingsV4", "SynergyTOSettingsV5"])
def test_tracking_as_given(shared_data: Path, tmp_path: Path, name: str) -> None:
    _check(_run_and_compare(shared_data, name, tmp_path), KNOWN_RMS_EXCEEDANCES.get(name, set()))


@pytest.mark.slow
@pytest.mark.parametrize("name,reproduces", [("TorqueVOSettingsV1", True), ("TorqueVOSettingsV2", True),
                                             ("SynergyVOSettingsV1", True), ("SynergyVOSettingsV2", False)])
def test_verification_as_given(shared_data: Path, tmp_path: Path, name: str, reproduces: bool) -> None:
    comp = _run_and_compare(shared_data, name, tmp_path)
    _check(comp)
    # its initial-guess (and tracked) folder is the original's TO results
    to_folder = Path(comp.ours.prepared.settings.initial_guess_directory)
    dq, dtau = _vo_versus_to(comp.ours, to_folder)
    if reproduces:
        assert dq <= 0.1 and dtau <= 0.1, (dq, dtau)
    else:
        # SynergyVOSettingsV2 adds terminal constraints (toe speed 13.1-13.2 m/s) that the TO V3
        # result does not meet: the motion must change a little (docs/treatment.md)
        ctx = comp.ours.prepared.built.context
        speed = float(comp.ours.result.value(ctx.final.marker_velocity("R_Toe")).ravel()[0])
        assert 13.1 - 1e-4 <= speed <= 13.2 + 1e-4 and dq <= 0.5, (speed, dq, dtau)


def _goal_met_or_explained(comp: Comparison, path: Path, **options) -> None:
    """Objective within 10 % of the original's, or IPOPT restarted from the original's solution
    and converged tightly finds nothing better than ours (<= 2 % above ours)."""
    if abs(comp.cost_ratio - 1) <= 0.10:
        return
    polish = _quiet(run_settings, path, guess_directory=_original(path), tolerance=1e-6, max_iterations=1000,
                    write_results=False, print_level=0, **options)
    assert polish.solution.success, polish.summary
    assert comp.ours.cost <= polish.cost * 1.02, (comp.report(), polish.cost)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["TorqueDOSettingsV1", "TorqueDOSettingsV2", "TorqueDOSettingsV5"])
def test_fixed_time_design_as_given(shared_data: Path, tmp_path: Path, name: str) -> None:
    comp = _run_and_compare(shared_data, name, tmp_path)
    _check(comp)
    _goal_met_or_explained(comp, _settings(shared_data, name))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["TorqueDOSettingsV3", "SynergyDOSettingsV1", "TorqueDOSettingsV4",
                                  "SynergyDOSettingsV2"])
def test_free_final_time_design_in_the_original_convention(shared_data: Path, tmp_path: Path, name: str) -> None:
    # the original keeps prescribed coordinates' data speeds when t_f changes; in that
    # convention its solution is (nearly) feasible for us
    options = {"rescale_prescribed_derivatives": False}
    comp = _run_and_compare(shared_data, name, tmp_path, **options)
    assert comp.ours.solution.success
    assert comp.ours.cost <= comp.theirs.initial_cost * (1 + 1e-6), comp.report()
    _goal_met_or_explained(comp, _settings(shared_data, name), **options)


#: torque DO V4's objective when IPOPT restarts from the original's solution at tol 1e-6
#: (benchmarks/bench_treatment.py, 2026-11-26; 0.0016270 from the tutorial's guess as well)
TORQUE_DO_V4_POLISHED = 0.001627


def test_design_goal_reaches_the_polished_minimum(shared_data: Path, tmp_path: Path) -> None:
    """Torque DO V4 (free final time, final toe speed goal) from the tutorial's guess: with
    the loose tolerance TO and VO use (1e-2 of the normalized objective) IPOPT stopped at
    0.001763, 8 % above the minimum it reaches from the original's solution; Design
    Optimization's own cap (1e-6) gets there."""
    path = _settings(shared_data, "TorqueDOSettingsV4")
    with pytest.warns(UserWarning, match=r"setup_nlp_tolerance=1 is looser than nmsm applies; IPOPT uses tol=1e-06"):
        ours = run_settings(path, results_directory=tmp_path / "do", print_level=0)
    assert ours.solution.success, ours.summary
    assert ours.cost <= TORQUE_DO_V4_POLISHED * 1.02, ours.cost

"""Known-answer NCP: synergies and moments generated in code are recovered; outputs and plots."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.core.convergence import CONVERGENCE_TABLE, read_convergence_table
from nmsm.examples.synthetic_ncp import run_synthetic_ncp
from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage
from nmsm.plots.ncp import plot_ncp_results
from nmsm.tools.dispatch import run_settings_file


@pytest.mark.parametrize("symmetric", [True, False])
def test_synthetic_synergies_are_recovered(tmp_path, symmetric) -> None:
    result = run_synthetic_ncp(tmp_path, symmetric=symmetric, n_synergies=3)
    run = result.run
    assert run.solver.success
    for side, similarity in result.cosine_similarity.items():
        assert similarity.min() >= 0.99, (side, similarity)
    peak = max(np.abs(m).max() for m in result.case.true_moments)
    assert result.moment_rms.max() <= 1e-4 * peak
    assert result.activation_rms <= 1e-3
    if symmetric:  # shared vectors: the left block mirrors the right one exactly
        layout = run.solution.layout
        right, left = run.solution.group_weights(0), run.solution.group_weights(1)
        order = [layout.groups[0].muscles.index(m.replace("_l", "_r")) for m in layout.groups[1].muscles]
        assert np.array_equal(left, right[:, order])


def test_synthetic_outputs(tmp_path) -> None:
    result = run_synthetic_ncp(tmp_path / "case")
    case, run = result.case, result.run
    folder = case.folder / "results"
    assert run.results_directory == folder
    weights = read_storage(folder / "synergyWeights.sto")
    assert weights.n_rows == 6 and set(weights.labels) == set(case.muscles)
    assert np.allclose(weights.data.max(axis=1), 1.0)
    assert list(weights.time) == [1, 2, 3, 4, 5, 6]
    commands = read_storage(folder / "trial_1_synergyCommands.sto")
    assert commands.labels == ("RightLeg_1", "RightLeg_2", "RightLeg_3", "LeftLeg_1", "LeftLeg_2", "LeftLeg_3")
    combined = read_storage(folder / "trial_1_combinedActivations.sto")
    mtp = read_storage(case.folder / "mtp" / "muscleActivations" / "trial_1_muscleActivations.sto")
    assert np.array_equal(combined.columns(list(mtp.labels)), mtp.data)  # MTP muscles keep MTP's activations
    moments = read_storage(folder / "modelMoments" / "trial_1_modeledMomentsNcp.sto")
    assert moments.labels[0] == "hip_flexion_r_moment"
    assert (folder / "modelMoments" / "trial_2_modeledMomentsMtpNcpCombined.sto").is_file()
    osimx = read_osimx(folder / "legs_mtp_ncp.osimx")
    assert [(s.muscle_group_name, s.num_synergies) for s in osimx.synergies] == [("RightLeg", 3), ("LeftLeg", 3)]
    assert osimx.muscles["soleus_r"].optimal_fiber_length == pytest.approx(read_osimx(case.osimx_file).muscles["soleus_r"].optimal_fiber_length)
    assert (folder / "NCPSettings.xml").is_file() and "moment RMS" in (folder / "commandWindowOutput.txt").read_text()
    figures = plot_ncp_results(folder)
    assert {p.name for p in figures} >= {"synergyVectors.png", "trial_1_momentMatching.png",
                                         "trial_2_activationMatching.png", "convergence.png"}
    assert all(p.stat().st_size > 10_000 for p in figures)
    history = read_convergence_table(folder / CONVERGENCE_TABLE)["ncp"]  # IPOPT's iterates, start included
    assert history.n_iterations == run.solver.iterations + 1
    assert history.cost[-1] == pytest.approx(run.solver.cost, rel=1e-6) and history.cost[-1] < history.cost[0]
    assert history.violation is not None and history.optimality is not None


def test_dispatcher_runs_ncp_settings(tmp_path) -> None:
    result = run_synthetic_ncp(tmp_path / "a")
    again = run_settings_file(result.case.settings_file, results_directory=tmp_path / "b", print_level=0)
    assert (tmp_path / "b" / "synergyWeights.sto").is_file()
    assert again.costs["total"] == pytest.approx(result.run.costs["total"], rel=1e-6)


def test_nmsm_run_command(tmp_path) -> None:
    from nmsm.cli import main
    from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case

    case = make_synthetic_ncp_case(tmp_path, n_trials=1, n_points=41)
    assert main(["run", str(case.settings_file)]) == 0
    assert (case.folder / "results" / "trial_1_synergyCommands.sto").is_file()


def test_results_read_back_for_treatment_optimization(tmp_path) -> None:
    from nmsm.model import load_model
    from nmsm.tools.ncp.outputs import layout_from_groups, read_solution

    result = run_synthetic_ncp(tmp_path)
    folder = result.case.folder / "results"
    osimx = read_osimx(folder / "legs_mtp_ncp.osimx")
    weights = read_storage(folder / "synergyWeights.sto")
    layout = layout_from_groups(load_model(result.case.model_file).groups,
                                [(s.muscle_group_name, s.num_synergies) for s in osimx.synergies], weights.labels)
    solution = read_solution(folder, layout, result.case.trials)
    for t in range(len(result.case.trials)):
        assert np.allclose(solution.activations(t), result.run.solution.activations(t), atol=1e-12)


def test_without_mtp_activations(tmp_path) -> None:
    """No MTP results: activation minimization covers every muscle; moments are still tracked."""
    from lxml import etree

    from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
    from nmsm.tools.ncp.run import run_settings

    case = make_synthetic_ncp_case(tmp_path, n_trials=1, n_points=51)
    tree = etree.parse(str(case.settings_file))
    tool = tree.getroot().find("NeuralControlPersonalizationTool")
    tool.find("mtp_results_directory").text = ""
    terms = tool.find("RCNLCostTermSet")
    for term in terms.findall("RCNLCostTerm"):
        if term.findtext("type") == "activation_tracking":
            term.find("type").text = "activation_minimization"
            term.find("max_allowable_error").text = "1"
    tree.write(str(case.settings_file))
    run = run_settings(case.settings_file, print_level=0)
    assert run.solver.success and not run.setup.inputs.mtp_muscles
    assert run.setup.mtp_activation_files is None
    assert np.isnan(run.metrics.activation_rms_pooled)
    peak = np.abs(case.true_moments[0]).max()
    assert run.metrics.moment_rms.max() < 0.02 * peak
    combined = read_storage(case.folder / "results" / "trial_1_combinedActivations.sto")
    assert np.allclose(combined.columns(list(run.solution.layout.muscles)), run.solution.activations(0))

"""``nmsm plot`` on Treatment Optimization results folders."""

from __future__ import annotations

import warnings
from pathlib import Path

from nmsm.cli import main
from nmsm.plots.treatment import is_treatment_results
from nmsm.tools.treatment.run import run_settings


def test_nmsm_plot_draws_a_tracking_results_folder(shared_data: Path, tmp_path: Path, capsys) -> None:
    settings = shared_data / "treatment" / "toy_arm" / "tracking_optimization" / "TorqueDrivenTOSettings.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(settings, results_directory=tmp_path / "to", print_level=0)
    assert is_treatment_results(tmp_path / "to")
    assert main(["plot", str(tmp_path)]) == 0
    assert "treatment" in capsys.readouterr().out
    figures = {p.name: p for p in (tmp_path / "to" / "plots").glob("*.png")}
    for name in ("arm1_kinematics.png", "arm1_loads.png", "arm1_controls.png"):
        assert name in figures and figures[name].stat().st_size > 10_000, sorted(figures)


def test_a_last_iterate_is_titled_as_not_converged(tmp_path: Path, monkeypatch) -> None:
    import matplotlib.figure

    from nmsm.io.storage import table_from_columns, write_storage
    from nmsm.plots.treatment import plot_treatment_results

    folder = tmp_path / "last_iterate"
    (folder / "IKData").mkdir(parents=True)
    t = [0.0, 0.5, 1.0]
    write_storage(folder / "arm1_states.sto", table_from_columns(t, {"q": [0.0, 0.1, 0.2], "q_u": [0.2, 0.2, 0.2]}))
    (folder / "diagnosis.txt").write_text("Diagnosis\n")
    titles = []
    original = matplotlib.figure.Figure.suptitle
    monkeypatch.setattr(matplotlib.figure.Figure, "suptitle",
                        lambda self, text, **kw: titles.append(text) or original(self, text, **kw))
    plot_treatment_results(folder)
    assert titles and all("NOT CONVERGED" in t for t in titles), titles


def test_compare_figures_through_the_collocation_polynomial(shared_data: Path, tmp_path: Path, capsys) -> None:
    """TO and DO of the toy arm: the states between the nodes follow each interval's
    polynomial (equal to the nodes at the interval starts); ``nmsm plot --compare`` draws the
    TO's figures with the DO overlaid, and the convergence figure from the IPOPT log."""
    import numpy as np

    from nmsm.io.storage import read_storage
    from nmsm.plots.treatment import ipopt_iterations
    from nmsm.tools.treatment.outputs import SAMPLES_PER_POINT

    toy = shared_data / "treatment" / "toy_arm"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(toy / "tracking_optimization" / "TorqueDrivenTOSettings.xml", results_directory=tmp_path / "to",
                     print_level=0)
        run_settings(toy / "design_optimization" / "TorqueDrivenDOSettings.xml", results_directory=tmp_path / "do",
                     print_level=0)
    nodes = read_storage(tmp_path / "to" / "arm1_states.sto")
    dense = read_storage(tmp_path / "to" / "Analysis" / "arm1_statesInterpolated.sto")
    intervals, points = 5, 10  # the toy arm's mesh
    per_interval = SAMPLES_PER_POINT * points
    assert dense.n_rows == intervals * per_interval + 1
    starts = dense.time[::per_interval]
    at_starts = [int(np.argmin(np.abs(nodes.time - t))) for t in starts[:-1]]
    np.testing.assert_allclose(nodes.time[at_starts], starts[:-1], atol=1e-12)
    np.testing.assert_allclose(dense.data[::per_interval][:-1], nodes.data[at_starts], atol=1e-9)
    iterations = ipopt_iterations(tmp_path / "to" / "arm1_ipopt.log")
    assert iterations.shape[0] >= 2 and iterations[0, 0] == 0
    assert main(["plot", "--compare", str(tmp_path / "to"), str(tmp_path / "do"), "-o", str(tmp_path / "figs")]) == 0
    assert "to vs" in capsys.readouterr().out
    names = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert names == ["compare_arm1_controls.png", "compare_arm1_convergence.png", "compare_arm1_kinematics.png",
                     "compare_arm1_loads.png"], names
    assert main(["plot", "--compare", str(tmp_path / "to")]) == 1  # one folder is nothing to compare

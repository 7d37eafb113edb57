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

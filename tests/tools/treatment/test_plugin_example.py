"""The installable plugin example (plugins_example/, distribution nmsm-stroke-example).

Its cost term and model function are declared by name in a Design Optimization settings
file and solved on a small mesh of the synergy-driven kicking data.
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import pytest
from lxml import etree

from nmsm.core.registry import get_registry

pytestmark = pytest.mark.skipif(
    importlib.util.find_spec("nmsm_stroke") is None,
    reason="nmsm_stroke is not installed (pip install ./plugins_example; CI installs it)",
)

EXAMPLE = Path(__file__).resolve().parents[3] / "plugins_example" / "examples" / "StrokeSynergyDOSettings.xml"


def test_plugin_classes_are_registered_under_their_distribution() -> None:
    registry = get_registry()
    items = {(it.kind, it.name): it for it in registry.items()}
    assert items[("cost", "synergy_amplitude_symmetry")].distribution == "nmsm-stroke-example"
    assert items[("modifier", "scaleSynergyActivation")].distribution == "nmsm-stroke-example"


def test_design_optimization_with_the_plugin(shared_data: Path, tmp_path: Path, monkeypatch) -> None:
    from nmsm.tools.treatment.run import run_settings

    # the example's paths are relative to the synergy kicking tutorial folder
    monkeypatch.chdir(shared_data / "treatment" / "synergy_kick_tutorial")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_settings(EXAMPLE, results_directory=tmp_path)
    assert run.solution.success, run.summary
    assert "synergy_amplitude_symmetry:RightLeg_1:RightLeg_4" in run.solution.term_costs
    # the modifier's parameter is optimized within its bounds and written out
    root = etree.parse(str(tmp_path / "drive_kick1_parameterSolution.xml")).getroot()
    value = float(root.find("RCNLParameters/RCNLParameterSet/values").text)
    assert 0.6 - 1e-8 <= value <= 1.0 + 1e-8
    # the symmetry term is active: RightLeg_1 and RightLeg_4 end with close RMS amplitudes
    ctx = run.prepared.built.context
    a1 = float(run.result.value(ctx.integrate(ctx.control("RightLeg_1") ** 2)).ravel()[0]) ** 0.5
    a4 = float(run.result.value(ctx.integrate(ctx.control("RightLeg_4") ** 2)).ravel()[0]) ** 0.5
    assert abs(a1 - a4) < 0.05 * 3
    # the synergy-driven results draw with `nmsm plot`'s treatment plotter
    from nmsm.plots.treatment import plot_treatment_results

    names = {p.name for p in plot_treatment_results(tmp_path, tmp_path / "plots")}
    assert {"drive_kick1_activations.png", "drive_kick1_kinematics.png"} <= names, names


def test_unknown_model_function_is_a_clear_error(shared_data: Path, tmp_path: Path, monkeypatch) -> None:
    from nmsm.errors import InputError
    from nmsm.tools.treatment.run import run_settings

    monkeypatch.chdir(shared_data / "treatment" / "synergy_kick_tutorial")
    text = EXAMPLE.read_text().replace("<model_functions>scaleSynergyActivation", "<model_functions>noSuchFunction")
    bad = EXAMPLE.parent / "StrokeSolverSettings.xml"
    settings = tmp_path / "bad.xml"
    settings.write_text(text.replace("StrokeSolverSettings.xml", str(bad)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InputError, match="unknown modifier 'noSuchFunction'.*scaleSynergyActivation"):
            run_settings(settings, results_directory=tmp_path / "out")

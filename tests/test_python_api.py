"""The Python API (``nmsm.run``, ``nmsm.run_pipeline``): wrong argument types name the argument."""

from __future__ import annotations

import pytest

import nmsm


@pytest.mark.parametrize("value", [None, 123, ["TO.xml"]])
def test_run_names_a_settings_file_that_is_not_a_path(value) -> None:
    with pytest.raises(TypeError, match=r"nmsm.run\(settings_file\): expected the path of a file .*, got "):
        nmsm.run(value)


def test_run_names_a_results_directory_that_is_not_a_path(tmp_path) -> None:
    with pytest.raises(TypeError, match=r"nmsm.run\(results_directory=...\): expected the path .*got int 5"):
        nmsm.run(tmp_path / "settings.xml", results_directory=5)


def test_run_pipeline_names_a_pipeline_file_that_is_not_a_path() -> None:
    with pytest.raises(TypeError, match=r"nmsm.run_pipeline\(pipeline_file\): .*got int 123"):
        nmsm.run_pipeline(123)


def test_run_with_plots_draws_the_figures_after_the_tool_wrote_its_results(tmp_path) -> None:
    """The tool's run draws nothing; ``nmsm.run(plots=True)`` draws every figure ``nmsm plot`` would."""
    import json

    from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case

    case = make_synthetic_jmp_case(tmp_path / "case", duration=0.5)
    plain = nmsm.run(case.settings_file, results_directory=tmp_path / "plain", quiet=True)
    assert not (plain.results_directory / "plots").exists()
    run = nmsm.run(case.settings_file, results_directory=tmp_path / "drawn", quiet=True, plots=True)
    tasks = json.loads((run.results_directory / "jmp_results.json").read_text(encoding="utf-8"))["tasks"]
    expected = {f"jmp_{task['folder']}.png" for task in tasks} | {"jmp_summary.png", "convergence.png"}
    assert {p.name for p in (run.results_directory / "plots").iterdir()} == expected

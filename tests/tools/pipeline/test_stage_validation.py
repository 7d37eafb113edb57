"""A TO -> VO -> DO pipeline on the torque kicking tutorial: stage settings are validated
(terms included) before anything runs or is emptied, errors name the user's settings file,
and ``--check`` validates and shows the run's wiring."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.tools.pipeline.runner import RAN, run_pipeline_file

TUTORIAL = "treatment/torque_kick_tutorial"
PIPELINE = """<NMSMPipelineDocument Version="1.5.3">
  <PipelineTool name="kick">
    <results_directory>results</results_directory>
    <input_model_file>KickingModel.osim</input_model_file>
    <data_directory>preprocessed</data_directory>
    <StageList>
      <Stage name="to"><settings_file>TO.xml</settings_file></Stage>
      <Stage name="vo"><settings_file>VO.xml</settings_file></Stage>
      <Stage name="do"><settings_file>DO.xml</settings_file></Stage>
    </StageList>
  </PipelineTool>
</NMSMPipelineDocument>
"""
TYPO = ("<type>controller_tracking</type>", "<type>controler_tracking</type>")


@pytest.fixture()
def kick(shared_data: Path, tmp_path: Path) -> Path:
    source = shared_data / TUTORIAL
    folder = tmp_path / "kick"
    folder.mkdir()
    shutil.copy(source / "KickingModel.osim", folder)
    shutil.copy(source / "GpopsSettings.xml", folder)
    shutil.copytree(source / "preprocessed", folder / "preprocessed")
    for code in ("TO", "VO", "DO"):
        text = (source / "CompletedSettingsFiles" / f"Torque{code}SettingsV1.xml").read_text()
        (folder / f"{code}.xml").write_text(text.replace(">gpopsSettings.xml<", ">GpopsSettings.xml<"))
    (folder / "pipeline.xml").write_text(PIPELINE)
    for path in [folder, *folder.rglob("*")]:
        path.chmod(path.stat().st_mode | 0o200)
    return folder


def _tree(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _wiring(summary: str, stage: str) -> list[str]:
    """The ``element <- source`` lines a summary shows under ``stage``."""
    lines = summary.splitlines()
    start = next(k for k, line in enumerate(lines) if line.split()[:1] == [stage] and line.startswith("  "))
    block = []
    for line in lines[start + 1:]:
        if not line.startswith("      "):
            break
        block.append(line.strip())
    return block


def _type_line(settings: Path) -> int:
    """The line of the <RCNLCostTerm> holding the misspelled type (the term registry names the term)."""
    lines = settings.read_text().splitlines()
    typo = next(k for k, line in enumerate(lines) if TYPO[1] in line)
    return next(k for k in range(typo, -1, -1) if "<RCNLCostTerm" in lines[k]) + 1


def test_stage_settings_are_checked_before_anything_runs_or_is_emptied(
    kick: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pipeline, do = kick / "pipeline.xml", kick / "DO.xml"
    # --check: the settings are validated, and the wiring shown is the run's
    assert main(["pipeline", "--check", str(pipeline)]) == 0
    out = capsys.readouterr().out
    assert "settings checked: to, vo, do" in out
    for stage, source in (("vo", "to"), ("do", "vo")):
        wiring = _wiring(out, stage)
        assert f"initial_guess_directory <- treatment_results from stage '{source}'" in wiring
        assert f"tracked_quantities_directory <- treatment_results from stage '{source}'" in wiring
    assert not (kick / "results").exists()
    # a misspelled term type: --check names DO.xml and the term's line
    good = do.read_text()
    do.write_text(good.replace(*TYPO))
    assert main(["pipeline", "--check", str(pipeline)]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"nmsm: error: {do}:{_type_line(do)}: <type>: unknown cost 'controler_tracking' for DO")
    assert "Traceback" not in err and not (kick / "results").exists()
    # the finished DO results survive the same typo in a real run
    do.write_text(good)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_pipeline_file(pipeline, log=None)
    assert {s.name: s.status for s in run.stages} == {"to": RAN, "vo": RAN, "do": RAN}
    before = _tree(kick / "results")
    assert any(name.startswith("do/") and name.endswith("_states.sto") for name in before)
    do.write_text(good.replace(*TYPO))
    with pytest.raises(InputError) as info:
        run_pipeline_file(pipeline, log=None)
    assert str(info.value).startswith(f"{do}:{_type_line(do)}: <type>: unknown cost 'controler_tracking'")
    assert "results/do.xml" not in str(info.value)
    assert _tree(kick / "results") == before


def _term_line(settings: Path, text: str) -> int:
    """The line of the first ``text`` after the settings' first <RCNLCostTerm>."""
    lines = settings.read_text().splitlines()
    term = next(k for k, line in enumerate(lines) if "<RCNLCostTerm" in line)
    return next(k for k in range(term, len(lines)) if text in lines[k]) + 1


def test_check_binds_the_terms_to_the_model(kick: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--check binds each stage's terms to its model and data without solving: a tracked
    coordinate the model lacks is named with the stage, settings file, line and element; a
    stage whose data an earlier stage makes is said to be bound when it runs; every stage's
    errors are reported together; nothing is written."""
    pipeline, to, do = kick / "pipeline.xml", kick / "TO.xml", kick / "DO.xml"
    good = to.read_text()
    cost = "<coordinate_list>hip_flexion_r knee_angle_r ankle_angle_r</coordinate_list>"
    line = _term_line(to, cost)
    lines = good.splitlines(keepends=True)
    lines[line - 1] = lines[line - 1].replace("knee_angle_r ", "knee_angel_r ")
    to.write_text("".join(lines))
    assert main(["pipeline", "--check", str(pipeline)]) == 1
    captured = capsys.readouterr()
    err = captured.err
    assert err.startswith(f"nmsm: error: {to}:{line}: <coordinate_list>: stage 'to' (to), binding its terms to its "
                          "model and data: term 'generalized_coordinate_tracking'"), err
    assert "coordinate 'knee_angel_r' is not in the model (expected one of pelvis_tilt," in err
    assert "terms of stage 'vo' are bound when it runs: its <initial_guess_directory> comes from stage 'to'" \
        in captured.out
    assert "terms of stage 'do' are bound when it runs" in captured.out
    assert "Traceback" not in err and not (kick / "results").exists()
    # with another stage's settings error, both are reported
    do.write_text(do.read_text().replace(*TYPO))
    assert main(["pipeline", "--check", str(pipeline)]) == 1
    err = capsys.readouterr().err
    assert "2 errors in the pipeline's stages" in err
    assert f"{to}:{line}: <coordinate_list>: stage 'to'" in err and "'knee_angel_r'" in err
    assert f"{do}:{_type_line(do)}: <type>: unknown cost 'controler_tracking'" in err
    # fixed: the terms bind, and the check passes
    to.write_text(good)
    do.write_text(do.read_text().replace(TYPO[1], TYPO[0]))
    assert main(["pipeline", "--check", str(pipeline)]) == 0
    assert "terms of stage 'to' bound to its model and data" in capsys.readouterr().out
    assert not (kick / "results").exists()


def test_check_writes_nothing_even_where_the_settings_save_a_surrogate(shared_data: Path, tmp_path: Path,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    """--check binds a synergy TO whose settings save the fitted surrogate: the surrogate is
    fitted to bind the terms but not saved (it was written next to the stage's settings)."""
    folder = tmp_path / "synergy"
    shutil.copytree(shared_data / "treatment" / "synergy_kick_tutorial", folder)
    for path in [folder, *folder.rglob("*")]:
        path.chmod(path.stat().st_mode | 0o200)
    settings = folder / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml"
    text = settings.read_text()
    assert "<save_surrogate_model>false</save_surrogate_model>" in text
    (folder / "CompletedSettingsFiles" / "TO.xml").write_text(
        text.replace("<save_surrogate_model>false</save_surrogate_model>", "<save_surrogate_model>true</save_surrogate_model>")
        .replace("<load_surrogate_model>true</load_surrogate_model>", "<load_surrogate_model>false</load_surrogate_model>"))
    (folder / "pipeline.xml").write_text(PIPELINE.replace('<Stage name="to"><settings_file>TO.xml</settings_file>',
                                                  '<Stage name="to"><settings_file>CompletedSettingsFiles/TO.xml'
                                                  '</settings_file><keep_settings_inputs>initial_guess_directory '
                                                  'tracked_quantities_directory</keep_settings_inputs>')
                                         .replace('      <Stage name="vo"><settings_file>VO.xml</settings_file></Stage>\n', "")
                                         .replace('      <Stage name="do"><settings_file>DO.xml</settings_file></Stage>\n', ""))
    before = _tree(folder)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["pipeline", "--check", str(folder / "pipeline.xml")]) == 0
    assert "terms of stage 'to' bound to its model and data" in capsys.readouterr().out
    assert _tree(folder) == before


def test_check_reports_an_unexpected_binding_error_with_the_others(kick: Path, monkeypatch: pytest.MonkeyPatch,
                                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """An exception other than nmsm's own while binding (e.g. bad data reaching numpy) is
    listed as the stage's error with its type, not a traceback."""
    import nmsm.tools.pipeline.validation as validation

    def broken(settings):
        raise ValueError("operands could not be broadcast together")

    monkeypatch.setattr(validation, "bind_treatment", broken)
    assert main(["pipeline", "--check", str(kick / "pipeline.xml")]) == 1
    err = capsys.readouterr().err
    assert "stage 'to' (to), binding its terms to its model and data: ValueError: operands could not" in err
    assert "Traceback" not in err

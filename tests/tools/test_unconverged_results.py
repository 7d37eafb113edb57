"""One unconverged-result policy for every tool (nmsm.core.unconverged): a solve stopped
before its stopping criterion writes its last iterate and ``diagnosis.txt`` into
``<results>/last_iterate/``, never the usual results, and raises SolverError (``nmsm run``
exits 1); ``accept_unconverged`` writes the usual results, each file stamped."""

from __future__ import annotations

import shutil
import warnings
from collections.abc import Callable
from pathlib import Path

import pytest

from nmsm.core.unconverged import DIAGNOSIS_FILE, LAST_ITERATE
from nmsm.errors import SolverError


def _visible(folder: Path) -> list[str]:
    """Top-level entries of a results folder, hidden records left out."""
    return sorted(p.name for p in folder.iterdir() if not p.name.startswith("."))


def _jmp(shared_data: Path, tmp_path: Path) -> tuple[Callable[..., object], str]:
    from nmsm.tools.jmp.run import run_settings

    settings = shared_data / "jmp/toy_simple_arm/ToySettingsFile.xml"
    limits = {"function_tolerance": 1e-30, "step_tolerance": 1e-30, "optimality_tolerance": 1e-30,
              "max_function_evaluations": 3}  # tolerances it cannot reach within 3 evaluations
    return (lambda out, **kw: run_settings(settings, results_directory=out, quiet=True, **limits, **kw)), "*.osim"


def _mtp(shared_data: Path, tmp_path: Path) -> tuple[Callable[..., object], str]:
    from tests.tools.mtp.test_mtp_bad_input import write_settings

    from nmsm.tools.mtp.run import run_settings

    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    shutil.copytree(tutorial / "preprocessed", tmp_path / "preprocessed")
    settings = write_settings(tmp_path, tutorial)
    return (lambda out, **kw: run_settings(settings, results_directory=out, max_iterations=1, **kw)), "*_mtp.osimx"


def _ncp(shared_data: Path, tmp_path: Path) -> tuple[Callable[..., object], str]:
    from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
    from nmsm.tools.ncp.run import run_settings

    case = make_synthetic_ncp_case(tmp_path / "ncp_case")
    return (lambda out, **kw: run_settings(case.settings_file, results_directory=out, max_iterations=1,
                                           print_level=0, **kw)), "*.osimx"


def _gcp(shared_data: Path, tmp_path: Path) -> tuple[Callable[..., object], str]:
    from nmsm.examples.synthetic_gcp import write_synthetic_gcp
    from nmsm.tools.gcp.run import run_settings

    case = write_synthetic_gcp(tmp_path / "gcp_case")
    return (lambda out, **kw: run_settings(case.settings_file, results_directory=out, max_iterations=1,
                                           update_motion=False, **kw)), "*.osimx"


TOOLS = {"JMP": _jmp, "MTP": _mtp, "NCP": _ncp, "GCP": _gcp}


@pytest.mark.parametrize("tool", list(TOOLS))
def test_an_unconverged_solve_keeps_only_its_last_iterate(shared_data: Path, tmp_path: Path, tool: str) -> None:
    run, result_glob = TOOLS[tool](shared_data, tmp_path)
    out = tmp_path / "results"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(SolverError) as caught:
            run(out)
    message = str(caught.value)
    assert "did not reach its stopping criterion" in message and "--accept-unconverged" in message
    assert caught.value.last_iterate_path == str(out / LAST_ITERATE)
    top = _visible(out)
    assert LAST_ITERATE in top and not list(out.glob(result_glob)), top
    if tool == "JMP":  # the only task is unconverged: nothing at the top but the folder
        assert top == [LAST_ITERATE]
    saved = out / LAST_ITERATE
    diagnosis = (saved / DIAGNOSIS_FILE).read_text()
    assert diagnosis.startswith("Diagnosis") and "did not reach its stopping criterion" in diagnosis
    stamped = next(saved.rglob(result_glob))
    assert "UNCONVERGED" in stamped.read_text()

    with warnings.catch_warnings(record=True) as caught_warnings:
        warnings.simplefilter("always")
        run(out, accept_unconverged=True)
    assert any("unconverged results were accepted" in str(w.message) for w in caught_warnings)
    written = list(out.glob(result_glob))
    assert written and all("UNCONVERGED" in p.read_text() for p in written)
    assert not (out / LAST_ITERATE).exists()  # the earlier run's last iterate was retired
    tables = [p for p in out.rglob("*.sto") if "superseded" not in p.parts]
    assert all("unconverged=" in p.read_text() for p in tables)


def test_stamped_files_read_back(tmp_path: Path) -> None:
    """Stamped tables and .osimx files are read by nmsm as before."""
    from nmsm.core.unconverged_stamp import stamp_unconverged
    from nmsm.io.osimx import read_osimx
    from nmsm.io.storage import read_storage, table_from_columns, write_storage

    table = table_from_columns([0.0, 0.1], {"a": [1.0, 2.0]})
    write_storage(tmp_path / "t.sto", table)
    (tmp_path / "m.osimx").write_text('<?xml version="1.0"?>\n<NMSMPipelineDocument Version="1.5.3"><OsimxModel '
                                      'name="m"><associated_osim_model>m.osim</associated_osim_model></OsimxModel>'
                                      '</NMSMPipelineDocument>\n')
    (tmp_path / "r.json").write_text('{"a": 1}')
    stamp_unconverged(tmp_path, "did not reach its stopping criterion: task 1 -- limit")
    assert read_storage(tmp_path / "t.sto").data.tolist() == table.data.tolist()
    assert read_osimx(tmp_path / "m.osimx").name == "m"
    assert "UNCONVERGED" in (tmp_path / "m.osimx").read_text()
    import json

    assert json.loads((tmp_path / "r.json").read_text())["a"] == 1


def test_nmsm_run_exits_1_and_accepts_with_the_option(shared_data: Path, tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    from nmsm.cli import main

    toy = shared_data / "jmp/toy_simple_arm"
    for name in ("ToySettingsFile.xml", "simple_arm_translated_away.osim", "simple_arm.trc"):
        shutil.copy(toy / name, tmp_path / name)
    settings = tmp_path / "ToySettingsFile.xml"
    text = settings.read_text()
    limits = "".join(f"<{name}>{value}</{name}>" for name, value in (
        ("function_tolerance", "1e-30"), ("step_tolerance", "1e-30"), ("optimality_tolerance", "1e-30"),
        ("max_function_evaluations", "3")))
    settings.write_text(text.replace("<JMPTaskList>", limits + "<JMPTaskList>", 1))
    out = tmp_path / "out"
    assert main(["run", str(settings), "-o", str(out)]) == 1
    assert "last_iterate" in capsys.readouterr().err
    assert _visible(out) == [LAST_ITERATE]
    assert main(["run", str(settings), "-o", str(out), "--accept-unconverged"]) == 0
    assert "UNCONVERGED" in (out / "translation_result_from_xml.osim").read_text()


def test_the_pipeline_option_reaches_every_optimizing_stage() -> None:
    """``nmsm pipeline --accept-unconverged``: the solving stages get ``accept_unconverged``
    (other stages nothing), without changing the caller's stage options; without it only the
    stages whose ``<accept_unconverged>`` is true."""
    from types import SimpleNamespace

    from nmsm.tools.pipeline.runner import _with_accept_unconverged

    def stage(name: str, tool: str, accept: bool = False) -> SimpleNamespace:
        return SimpleNamespace(name=name, kind=SimpleNamespace(tool_element=tool), accept_unconverged=accept)

    spec = SimpleNamespace(stages=[stage("jmp", "JointModelPersonalizationTool"),
                                   stage("analysis", "ModelAnalysisTool"),
                                   stage("gcp", "GroundContactPersonalizationTool", accept=True),
                                   stage("to", "TrackingOptimizationTool")])
    given = {"gcp": {"max_iterations": 5}}
    assert _with_accept_unconverged(spec, given, False) == {"gcp": {"max_iterations": 5, "accept_unconverged": True}}
    options = _with_accept_unconverged(spec, given, True)
    assert options == {"jmp": {"accept_unconverged": True}, "to": {"accept_unconverged": True},
                       "gcp": {"max_iterations": 5, "accept_unconverged": True}}
    assert given == {"gcp": {"max_iterations": 5}}


def _one_stage_pipeline(folder: Path, tool: str, accept: str) -> Path:
    path = folder / "pipeline.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.3"><PipelineTool name="p">
  <results_directory>results</results_directory>
  <StageList>
    <Stage name="s">
      <accept_unconverged>{accept}</accept_unconverged>
      <{tool}/>
    </Stage>
  </StageList>
</PipelineTool></NMSMPipelineDocument>
""")
    return path


def test_a_stage_accepts_unconverged_results_by_its_element(tmp_path: Path) -> None:
    """``<accept_unconverged>`` of a pipeline ``<Stage>``: read as a boolean, only in a stage
    that solves an optimization, each refusal at its line."""
    from nmsm.errors import InputError
    from nmsm.tools.pipeline.pipeline_file import read_pipeline

    stage = read_pipeline(_one_stage_pipeline(tmp_path, "GroundContactPersonalizationTool", "true")).stages[0]
    assert stage.accept_unconverged
    assert not read_pipeline(_one_stage_pipeline(tmp_path, "GroundContactPersonalizationTool", "")).stages[0] \
        .accept_unconverged
    for tool, accept, message in (("GroundContactPersonalizationTool", "perhaps", "not a boolean"),
                                  ("ModelAnalysisTool", "true", "solves no optimization")):
        with pytest.raises(InputError, match=message) as info:
            read_pipeline(_one_stage_pipeline(tmp_path, tool, accept))
        assert info.value.line == 5 and info.value.element == "<accept_unconverged>"

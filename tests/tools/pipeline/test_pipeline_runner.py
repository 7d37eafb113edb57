"""The pipeline runner on fake stages: wiring, skipping up-to-date stages, resuming after a
stop, re-running what changed, settings written into the results tree, bad input."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from fake_stages import CALLS, FAIL_NEXT, STOP_NEXT, fake_kinds  # noqa: E402

from nmsm.errors import InputError, SolverError  # noqa: E402
from nmsm.tools.pipeline.runner import RAN, UP_TO_DATE, run_pipeline_file  # noqa: E402
from nmsm.tools.pipeline.state import MARKER, STATE_FILE  # noqa: E402

MAKER_SETTINGS = """<NMSMPipelineDocument Version="1.5.3"><FakeMakerTool>
  <results_directory>ignored_out</results_directory>
  <input_model_file>model.osim</input_model_file>
  <output_model_file>made.osim</output_model_file>
  <offset>{offset}</offset>
</FakeMakerTool></NMSMPipelineDocument>
"""


def _pipeline(folder: Path, *, offset: str = "1", order: str = "maker fitter", fitter_data: str = "data",
              keep: str = "") -> Path:
    (folder / "maker.xml").write_text(MAKER_SETTINGS.format(offset=offset))
    stages = {
        "maker": '<Stage name="make"><settings_file>maker.xml</settings_file></Stage>',
        "fitter": (f'<Stage name="fit"><keep_settings_inputs>{keep}</keep_settings_inputs>'
                   f'<FakeFitterTool><results_directory/><input_model_file>model.osim</input_model_file>'
                   f'<data_directory>{fitter_data}</data_directory></FakeFitterTool></Stage>'),
    }
    body = "".join(stages[name] for name in order.split())
    path = folder / "pipeline.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.3"><PipelineTool name="fake">
  <results_directory>results</results_directory>
  <StageList>{body}</StageList>
</PipelineTool></NMSMPipelineDocument>
""")
    return path


@pytest.fixture()
def case(tmp_path: Path):
    (tmp_path / "model.osim").write_text("<model/>\n")
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "trial_1.sto").write_text("1 2 3\n")
    with fake_kinds():
        yield tmp_path


def _statuses(run) -> dict[str, str]:
    return {s.name: s.status for s in run.stages}


def test_chain_wires_outputs_and_writes_stage_settings(case: Path) -> None:
    run = run_pipeline_file(_pipeline(case), log=None)
    assert _statuses(run) == {"make": RAN, "fit": RAN}
    results = case / "results"
    # the fitter read the maker's model, not the settings' own model.osim
    assert (results / "fit" / "part1.txt").read_text() == "<model/>\n<!-- offset 1 -->\n"
    assert run.stage("fit").wired["input_model_file"] == "model from stage 'make'"
    # each stage's settings are in the tree, with tree paths relative (movable) and inputs absolute
    text = (results / "fit.xml").read_text()
    assert "<input_model_file>make/made.osim</input_model_file>" in text
    assert f"<data_directory>{(case / 'data').resolve()}</data_directory>" in text
    assert "<results_directory>fit</results_directory>" in text
    state = json.loads((results / STATE_FILE).read_text())
    assert set(state["stages"]) == {"make", "fit"}
    assert state["stages"]["fit"]["outputs"] == {"osimx": "fit/fit_mtp.osimx", "mtp_results": "fit"}


def test_second_run_skips_everything_and_changes_rerun_downstream(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    CALLS.clear()
    run = run_pipeline_file(pipeline, log=None)
    assert _statuses(run) == {"make": UP_TO_DATE, "fit": UP_TO_DATE}
    assert CALLS == []
    # a new data file changes only the fitter's inputs
    (case / "data" / "trial_2.sto").write_text("4 5 6\n")
    run = run_pipeline_file(pipeline, log=None)
    assert _statuses(run) == {"make": UP_TO_DATE, "fit": RAN}
    assert "trial_2.sto" in (case / "results" / "fit" / "fit_mtp.osimx").read_text()
    # a changed maker setting re-runs the maker and, through its new model, the fitter
    CALLS.clear()
    run = run_pipeline_file(_pipeline(case, offset="2"), log=None)
    assert _statuses(run) == {"make": RAN, "fit": RAN}
    assert [c[0] for c in CALLS] == ["maker", "fitter"]
    # a changed model file changes the maker's inputs
    (case / "model.osim").write_text("<model version='2'/>\n")
    run = run_pipeline_file(pipeline, log=None)
    assert _statuses(run)["make"] == RAN


def test_stopped_pipeline_resumes_without_redoing_finished_stages(case: Path) -> None:
    pipeline = _pipeline(case)
    STOP_NEXT.add("fitter")
    with pytest.raises(KeyboardInterrupt):
        run_pipeline_file(pipeline, log=None)
    state = json.loads((case / "results" / STATE_FILE).read_text())
    assert list(state["stages"]) == ["make"]  # the stopped stage is not recorded
    assert not (case / "results" / "fit").exists()  # nor is its partial output left
    CALLS.clear()
    run = run_pipeline_file(pipeline, log=None)
    assert _statuses(run) == {"make": UP_TO_DATE, "fit": RAN}
    assert [c[0] for c in CALLS] == ["fitter"]


def test_a_stopped_or_failed_rerun_keeps_the_stage_s_earlier_results(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    results = case / "results"
    fit_before, settings_before = _tree(results / "fit"), (results / "fit.xml").read_bytes()
    (case / "data" / "extra.txt").write_text("new data: the fit runs again")
    STOP_NEXT.add("fitter")
    with pytest.raises(KeyboardInterrupt):  # stopped after writing part of its output
        run_pipeline_file(pipeline, log=None)
    assert _tree(results / "fit") == fit_before and (results / "fit.xml").read_bytes() == settings_before
    assert not any(p.name.startswith(".fit") for p in results.iterdir())
    (case / "maker.xml").write_text((case / "maker.xml").read_text().replace("made.osim", "made.bad"))
    make_before = _tree(results / "make")
    with pytest.raises(InputError, match="the maker cannot write .bad files"):  # found by the tool while running
        run_pipeline_file(pipeline, log=None)
    assert _tree(results / "make") == make_before
    (case / "maker.xml").write_text((case / "maker.xml").read_text().replace("made.bad", "made.osim"))
    CALLS.clear()
    run = run_pipeline_file(pipeline, log=None)  # the kept results are recorded with their old inputs
    assert _statuses(run) == {"make": UP_TO_DATE, "fit": RAN}
    assert "extra.txt" in (results / "fit" / "fit_mtp.osimx").read_text()


def test_a_solver_failure_keeps_its_diagnosis_and_the_earlier_results(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    fit = case / "results" / "fit"
    before = _tree(fit)
    (case / "data" / "extra.txt").write_text("new data: the fit runs again")
    FAIL_NEXT.add("fitter")
    with pytest.raises(SolverError, match="last iterate and diagnosis saved in"):
        run_pipeline_file(pipeline, log=None)
    assert (fit / "last_iterate" / "diagnosis.txt").is_file()
    assert {f"superseded/{name}": data for name, data in before.items()} == {
        name: data for name, data in _tree(fit).items() if name.startswith("superseded/")}
    assert not (fit / "fit_mtp.osimx").exists()  # nothing at the top looks like a result of this run


def test_moved_results_tree_stays_up_to_date(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    moved = case / "moved"
    moved.mkdir()
    for name in ("model.osim", "maker.xml", "pipeline.xml"):
        (moved / name).write_bytes((case / name).read_bytes())
    (case / "data").rename(moved / "data")
    (case / "results").rename(moved / "results")
    CALLS.clear()
    run = run_pipeline_file(moved / "pipeline.xml", log=None)
    assert _statuses(run) == {"make": UP_TO_DATE, "fit": UP_TO_DATE}
    assert CALLS == []


def test_deleted_or_edited_outputs_rerun_the_stage(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    (case / "results" / "make" / "made.osim").write_text("edited\n")
    run = run_pipeline_file(pipeline, log=None)
    assert _statuses(run) == {"make": RAN, "fit": UP_TO_DATE}  # same model re-made: fitter inputs unchanged


def test_keep_settings_inputs_leaves_the_element(case: Path) -> None:
    run = run_pipeline_file(_pipeline(case, keep="input_model_file"), log=None)
    assert (case / "results" / "fit" / "part1.txt").read_text() == "<model/>\n"
    assert "input_model_file" not in run.stage("fit").wired


def test_until_and_only_select_stages(case: Path) -> None:
    pipeline = _pipeline(case)
    run = run_pipeline_file(pipeline, until="make", log=None)
    assert _statuses(run) == {"make": RAN, "fit": "not selected"}
    run = run_pipeline_file(pipeline, only=["fit"], log=None)
    assert _statuses(run) == {"make": UP_TO_DATE, "fit": RAN}
    run_pipeline_file(_pipeline(case, offset="5"), log=None, until="make")
    run_pipeline_file(_pipeline(case, offset="6"), log=None, check_only=True)
    with pytest.raises(InputError, match="stage 'fit'.*needs the outputs of stage 'make'"):
        run_pipeline_file(_pipeline(case, offset="7"), only=["fit"], log=None)


def test_rebuild_and_force(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    assert _statuses(run_pipeline_file(pipeline, force=["fit"], log=None)) == {"make": UP_TO_DATE, "fit": RAN}
    assert _statuses(run_pipeline_file(pipeline, rebuild=True, log=None)) == {"make": RAN, "fit": RAN}


# ---- bad input ---------------------------------------------------------------------------------
def test_impossible_order_names_both_stages(case: Path) -> None:
    with pytest.raises(InputError, match=r"stage 'make' \(maker\): cannot run after stage 'fit' \(fitter\)"):
        run_pipeline_file(_pipeline(case, order="fitter maker"), log=None)


def test_missing_input_names_stage_and_piece(case: Path) -> None:
    with pytest.raises(InputError) as info:
        run_pipeline_file(_pipeline(case, order="fitter", fitter_data="no_such_folder"), log=None)
    text = str(info.value)
    assert "stage 'fit' (fitter)" in text and "data folder" in text and "no_such_folder" in text
    assert "an earlier" in text and "<data_directory>" in text


def test_results_tree_from_older_version(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    state_file = case / "results" / STATE_FILE
    data = json.loads(state_file.read_text())
    data["version"] = 0
    state_file.write_text(json.dumps(data))
    with pytest.raises(InputError, match="older nmsm pipeline.*state format version 0"):
        run_pipeline_file(pipeline, log=None)
    data["version"] = 1
    del data["stages"]["fit"]["input_digest"]
    state_file.write_text(json.dumps(data))
    with pytest.raises(InputError, match="stage 'fit': record lacks input_digest"):
        run_pipeline_file(pipeline, log=None)


def test_unknown_stage_tool_and_duplicate_names(case: Path) -> None:
    path = case / "bad.xml"
    path.write_text('<NMSMPipelineDocument Version="1.5.3"><PipelineTool><results_directory>r</results_directory>'
                    '<StageList><Stage><NoSuchTool/></Stage></StageList></PipelineTool></NMSMPipelineDocument>')
    with pytest.raises(InputError, match="<NoSuchTool> is not a pipeline stage"):
        run_pipeline_file(path, log=None)
    path.write_text('<NMSMPipelineDocument Version="1.5.3"><PipelineTool><results_directory>r</results_directory>'
                    '<StageList><Stage name="a"><settings_file>maker.xml</settings_file></Stage>'
                    '<Stage name="a"><settings_file>maker.xml</settings_file></Stage></StageList>'
                    '</PipelineTool></NMSMPipelineDocument>')
    (case / "maker.xml").write_text(MAKER_SETTINGS.format(offset=0))
    with pytest.raises(InputError, match="stage name 'a' used twice"):
        run_pipeline_file(path, log=None)


def test_stage_folder_the_runner_did_not_write_is_never_emptied(case: Path) -> None:
    """A results tree without pipeline_state.json (an older run, another tool) keeps its files."""
    pipeline = _pipeline(case)
    old = case / "results" / "make" / "old_result.osim"
    old.parent.mkdir(parents=True)
    old.write_text("old")
    with pytest.raises(InputError) as info:
        run_pipeline_file(pipeline, log=None)
    text = str(info.value)
    assert "stage 'make'" in text and str(old.parent) in text and "not written by this pipeline" in text
    assert old.read_text() == "old" and CALLS == []
    assert not (case / "results" / STATE_FILE).exists() and not (case / "results" / "pipeline.xml").exists()
    old.unlink()  # an empty folder is used as it is
    assert _statuses(run_pipeline_file(pipeline, log=None)) == {"make": RAN, "fit": RAN}


def test_stage_folder_holding_an_input_is_refused(case: Path) -> None:
    # a stage named like an input folder inside the results folder
    data = case / "res" / "data"
    data.mkdir(parents=True)
    (data / "trial_1.sto").write_text("INPUT\n")
    pipeline = _pipeline(case, fitter_data="res/data")
    pipeline.write_text(pipeline.read_text().replace("<results_directory>results<", "<results_directory>res<")
                        .replace('name="make"', 'name="data"'))
    with pytest.raises(InputError, match=r"stage 'data' \(maker\): its results folder .*res/data holds "
                                         r"<data_directory> of stage 'fit'"):
        run_pipeline_file(pipeline, log=None)
    assert (data / "trial_1.sto").read_text() == "INPUT\n" and CALLS == []
    # a stage's own results read by a later stage are outputs (as if wired): the stage reruns
    run_pipeline_file(_pipeline(case), log=None)
    made = case / "results" / "make" / "made.osim"
    run = run_pipeline_file(_pipeline(case, offset="2", fitter_data="results/make"), log=None)
    assert _statuses(run) == {"make": RAN, "fit": RAN}
    assert "made.osim" in (case / "results" / "fit" / "fit_mtp.osimx").read_text()
    # but a stage reading its own results folder would lose its input: refused, even though the runner wrote it
    pipeline = _pipeline(case, offset="3")
    (case / "maker.xml").write_text((case / "maker.xml").read_text().replace("<input_model_file>model.osim<",
                                                                             f"<input_model_file>{made}<"))
    with pytest.raises(InputError, match=r"stage 'make' \(maker\): its results folder .* holds <input_model_file> "
                                         r"of stage 'make'"):
        run_pipeline_file(pipeline, log=None)
    assert made.read_text() == "<model/>\n<!-- offset 2 -->\n"


def test_results_directory_of_the_pipeline_folder_is_refused(case: Path) -> None:
    pipeline = _pipeline(case)
    text = pipeline.read_text().replace("<results_directory>results<", "<results_directory>.<")
    pipeline.write_text(text)
    before = sorted(p.name for p in case.iterdir())
    with pytest.raises(InputError, match=r"pipeline.xml: <results_directory>: the results folder .* is the pipeline "
                                         r"file's own folder.*\(expected a folder of its own"):
        run_pipeline_file(pipeline, log=None)
    assert sorted(p.name for p in case.iterdir()) == before and pipeline.read_text() == text


# ---- settings validated before anything runs or is emptied -----------------------------------------
def _tree(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_settings_error_names_the_users_file_and_keeps_finished_results(case: Path) -> None:
    """A typo in a finished stage's settings: the error is at the user's file and line, and the
    stage's earlier results (and every other file of the tree) are left as they were."""
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    before = _tree(case / "results")
    CALLS.clear()
    with pytest.raises(InputError) as info:
        run_pipeline_file(_pipeline(case, offset="1.5x"), log=None)
    assert str(info.value).startswith(f"{case / 'maker.xml'}:5: <offset>: '1.5x' is not a number")
    assert CALLS == [] and _tree(case / "results") == before
    # embedded settings: the pipeline file and its line
    pipeline = _pipeline(case)
    text = pipeline.read_text().replace("<results_directory/>", "<results_directory/><degree>2.5</degree>")
    pipeline.write_text(text)
    with pytest.raises(InputError, match=f"^{pipeline}:3: <degree>: '2.5' is not an integer"):
        run_pipeline_file(pipeline, log=None)
    assert CALLS == [] and _tree(case / "results") == before


def test_tool_error_in_the_written_settings_points_at_the_users_file(case: Path) -> None:
    """An error the tool finds while running, at a line of the copy the runner wrote into the
    results tree (<stage>.xml), names the user's settings file and the element's line there."""
    _pipeline(case)
    settings = case / "maker.xml"
    settings.write_text(settings.read_text().replace("made.osim", "made.bad"))
    with pytest.raises(InputError) as info:
        run_pipeline_file(case / "pipeline.xml", log=None)
    assert str(info.value) == (f"{settings}:4: <output_model_file>: the maker cannot write .bad files "
                               "(expected a .osim name)")


def test_check_validates_settings_and_shows_the_run_s_wiring(case: Path) -> None:
    pipeline = _pipeline(case)
    run = run_pipeline_file(pipeline, check_only=True, log=None)
    assert _statuses(run) == {"make": "would run", "fit": "would run"}
    assert not (case / "results").exists()
    # the same wiring lines as the real run
    real = run_pipeline_file(pipeline, log=None)
    assert run.stage("fit").wired == real.stage("fit").wired
    assert "input_model_file <- model from stage 'make'" in run.summary()
    # an edited maker: both would run again, still wired from the maker
    run = run_pipeline_file(_pipeline(case, offset="3"), check_only=True, log=None)
    assert _statuses(run) == {"make": "would run", "fit": "would run"}
    assert run.stage("fit").wired == real.stage("fit").wired
    before = _tree(case / "results")
    with pytest.raises(InputError, match=r"maker.xml:5: <offset>: 'x' is not a number"):
        run_pipeline_file(_pipeline(case, offset="x"), check_only=True, log=None)
    # --check reports every stage's error; a run stops at the first
    pipeline = _pipeline(case, offset="x")
    pipeline.write_text(pipeline.read_text().replace("<results_directory/>", "<results_directory/><degree>a</degree>"))
    with pytest.raises(InputError) as info:
        run_pipeline_file(pipeline, check_only=True, log=None)
    assert str(info.value).splitlines() == [
        "2 errors in the pipeline's stages:",
        f"  {case / 'maker.xml'}:5: <offset>: 'x' is not a number (expected a number)",
        f"  {pipeline}:3: <degree>: 'a' is not an integer (expected an integer)"]
    with pytest.raises(InputError, match="maker.xml:5: <offset>"):
        run_pipeline_file(pipeline, log=None)
    assert _tree(case / "results") == before


# ---- a damaged pipeline_state.json and --rebuild -----------------------------------------------------
def test_rebuild_works_on_a_damaged_state(case: Path) -> None:
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    state_file = case / "results" / STATE_FILE
    good = state_file.read_text()
    for damage in ("truncated", "missing field"):
        if damage == "truncated":
            state_file.write_text(good[:300])
        else:
            data = json.loads(good)
            del data["stages"]["make"]["outputs"]
            state_file.write_text(json.dumps(data))
        damaged = state_file.read_text()
        with pytest.raises(InputError, match=r"pipeline_state.json: .*run 'nmsm pipeline --rebuild PIPELINE.xml' "
                                             r"to redo every stage"):
            run_pipeline_file(pipeline, log=None)
        run = run_pipeline_file(pipeline, rebuild=True, check_only=True, log=None)
        assert _statuses(run) == {"make": "would run", "fit": "would run"} and state_file.read_text() == damaged
        run = run_pipeline_file(pipeline, rebuild=True, log=None)
        assert _statuses(run) == {"make": RAN, "fit": RAN}
        assert (case / "results" / (STATE_FILE + ".damaged")).read_text() == damaged  # kept for inspection
        assert set(json.loads(state_file.read_text())["stages"]) == {"make", "fit"}
        assert _statuses(run_pipeline_file(pipeline, log=None)) == {"make": UP_TO_DATE, "fit": UP_TO_DATE}


def test_rebuild_on_an_unreadable_state_never_empties_an_unmarked_folder(case: Path) -> None:
    """With pipeline_state.json unreadable, only folders holding the runner's marker are the
    runner's: a stage folder without it (a tree of an older nmsm, files put there by hand) is kept."""
    pipeline = _pipeline(case)
    run_pipeline_file(pipeline, log=None)
    results = case / "results"
    (results / "fit" / MARKER).unlink()
    (results / STATE_FILE).write_text('{"format": "nmsm-pipeline-state", "vers')
    before = _tree(results)
    CALLS.clear()
    with pytest.raises(InputError) as info:
        run_pipeline_file(pipeline, rebuild=True, log=None)
    text = str(info.value)
    assert f"its results folder {results / 'fit'} already exists and was not written by this pipeline" in text
    assert "is damaged (unreadable pipeline state" in text and f"holds no {MARKER} marker" in text
    assert _tree(results) == before and CALLS == []


def test_one_stage_name_as_a_string_and_stage_options_checked_first(case: Path) -> None:
    pipeline = _pipeline(case)
    run = run_pipeline_file(pipeline, only="make", log=None)  # not the letters m, a, k, e
    assert _statuses(run) == {"make": RAN, "fit": "not selected"}
    CALLS.clear()
    with pytest.raises(InputError, match=r"stage_options for 'fitt', which is not a stage of the pipeline "
                                         r"\(expected stage names: make, fit\)"):
        run_pipeline_file(pipeline, stage_options={"fitt": {}}, log=None)
    assert CALLS == []


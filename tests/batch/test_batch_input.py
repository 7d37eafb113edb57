"""Bad batch input is refused before any run starts (no cluster, nothing written); the batch
file of ``nmsm print-xml batch`` reads."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))

from batch_helpers import sweep, write_batch  # noqa: E402

from nmsm.batch import run  # noqa: E402
from nmsm.batch.batch_file import read_batch  # noqa: E402
from nmsm.cli import main  # noqa: E402
from nmsm.errors import InputError  # noqa: E402


def _refused(batch: Path, *fragments: str, **options) -> InputError:
    with pytest.raises(InputError) as caught:
        run(batch, log=None, **options)
    for fragment in fragments:
        assert fragment in str(caught.value), str(caught.value)
    assert not (batch.parent / "out").exists()  # nothing written
    return caught.value


def test_an_element_path_the_settings_do_not_have(jmp_case, tmp_path) -> None:
    settings = jmp_case.settings_file
    batch = write_batch(tmp_path, f"""\
        <Sweep name="s"><settings_file>{settings}</settings_file>
          <Parameter name="p"><element>JMPTaskList/JMPTask/no_such_element</element><values>1 2</values></Parameter>
        </Sweep>""")
    error = _refused(batch, "sweep 's', parameter 'p'", "'JMPTaskList/JMPTask/no_such_element' matches no element")
    assert error.file == str(batch) and error.line is not None


def test_a_path_matching_several_elements_is_refused(jmp_case, tmp_path) -> None:
    both_joints = "JMPTaskList/JMPTask/JMPJointSet/JMPJoint/parent_frame_transformation/orientation_bounds"
    batch = write_batch(tmp_path, f"""\
        <Sweep name="s"><settings_file>{jmp_case.settings_file}</settings_file>
          <Parameter name="p"><element>{both_joints}</element><values>1</values></Parameter>
        </Sweep>""")
    _refused(batch, "matches 2 elements", "[@name='...']")


def test_a_value_the_tool_cannot_read(jmp_case, tmp_path) -> None:
    batch = write_batch(tmp_path, sweep(jmp_case.settings_file, values="0.2 abc"))
    _refused(batch, "variant 'knee_bounds=abc'", "knee_bounds = 'abc'", "<orientation_bounds>")


def test_a_dependency_cycle(jmp_case, tmp_path) -> None:
    settings = jmp_case.settings_file
    batch = write_batch(tmp_path, f"""\
        <Run name="a"><settings_file>{settings}</settings_file><depends_on>c</depends_on></Run>
        <Run name="b"><settings_file>{settings}</settings_file><depends_on>a</depends_on></Run>
        <Run name="c"><settings_file>{settings}</settings_file><depends_on>b</depends_on></Run>""")
    _refused(batch, "a dependency cycle: a -> c -> b -> a")


def test_two_runs_writing_one_results_folder(jmp_case, tmp_path) -> None:
    settings = jmp_case.settings_file
    batch = write_batch(tmp_path, f"""\
        <Run name="a"><settings_file>{settings}</settings_file><results_directory>P01/jmp</results_directory></Run>
        <Run name="b"><settings_file>{settings}</settings_file><results_directory>P01/jmp</results_directory></Run>""")
    _refused(batch, "runs 'a' and 'b' write the same results folder")
    batch = write_batch(tmp_path, f"""\
        <Run name="a"><settings_file>{settings}</settings_file><results_directory>P01</results_directory></Run>
        <Run name="b"><settings_file>{settings}</settings_file><results_directory>P01/jmp</results_directory></Run>""")
    _refused(batch, "inside the results folder of run 'a'")


def test_names_that_are_no_run_and_a_warm_start_of_a_tool_without_one(jmp_case, tmp_path) -> None:
    settings = jmp_case.settings_file
    batch = write_batch(tmp_path, f"""<Run name="a"><settings_file>{settings}</settings_file>
        <depends_on>nobody</depends_on></Run>""")
    _refused(batch, "'a' depends on 'nobody', which is no run or sweep")
    batch = write_batch(tmp_path, f"""\
        <Run name="a"><settings_file>{settings}</settings_file></Run>
        <Run name="b"><settings_file>{settings}</settings_file><warm_start_from>a</warm_start_from></Run>""")
    _refused(batch, "<JointModelPersonalizationTool> has no <initial_guess_directory>")


def test_a_results_folder_the_batch_did_not_write_is_left_alone(jmp_case, tmp_path) -> None:
    batch = write_batch(tmp_path, f'<Run name="a"><settings_file>{jmp_case.settings_file}</settings_file></Run>')
    mine = tmp_path / "out" / "a"
    mine.mkdir(parents=True)
    (mine / "notes.txt").write_text("mine", encoding="utf-8")
    with pytest.raises(InputError, match="exists and was not written by this batch"):
        run(batch, log=None)
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["a"]
    assert (mine / "notes.txt").read_text(encoding="utf-8") == "mine"


def test_a_scheduler_that_does_not_answer(jmp_case, tmp_path) -> None:
    batch = write_batch(tmp_path, f'<Run name="a"><settings_file>{jmp_case.settings_file}</settings_file></Run>')
    _refused(batch, "the scheduler at tcp://127.0.0.1:9 did not answer within 1 s", scheduler="tcp://127.0.0.1:9",
             timeout=1.0)
    _refused(batch, "--workers or --scheduler, not both", scheduler="tcp://127.0.0.1:9", workers=2)


def test_the_printed_batch_file_reads(tmp_path, capsys) -> None:
    assert main(["print-xml", "batch"]) == 0
    (tmp_path / "batch.xml").write_text(capsys.readouterr().out, encoding="utf-8")
    (tmp_path / "P01").mkdir()
    for name in ("pipeline.xml", "do.xml"):
        (tmp_path / "P01" / name).write_text("<x/>", encoding="utf-8")
    spec = read_batch(tmp_path / "batch.xml")
    assert [(e.name, e.kind, e.is_sweep) for e in spec.entries] == [("P01", "pipeline", False),
                                                                    ("P01_weakness", "settings", True)]
    assert [p.name for p in spec.entries[1].parameters] == ["strength", "tracking_error"]


def test_the_command_reports_bad_input_in_one_line(jmp_case, tmp_path, capsys) -> None:
    settings = jmp_case.settings_file
    batch = write_batch(tmp_path, f"""\
        <Run name="a"><settings_file>{settings}</settings_file><depends_on>b</depends_on></Run>
        <Run name="b"><settings_file>{settings}</settings_file><depends_on>a</depends_on></Run>""")
    assert main(["batch", str(batch), "--workers", "2"]) == 1
    error = capsys.readouterr().err.strip()
    assert error.startswith(f"nmsm: error: {batch}: <depends_on>: a dependency cycle: a -> b -> a"), error
    assert "\n" not in error and not (tmp_path / "out").exists()

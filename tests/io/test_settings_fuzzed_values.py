"""Settings values found by the fuzz audit of the shared settings files (one element changed at a
time): each is one clear InputError naming the file, the element and what was expected, before
anything runs or is written."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.settings.reader import read_settings_document


def _copy(shared_data: Path, folder: str, tmp_path: Path) -> Path:
    target = tmp_path / Path(folder).name
    shutil.copytree(shared_data / folder, target)
    return target


@pytest.mark.parametrize("text", ["1e308", "1e10", "-3e9"])
def test_an_integer_beyond_a_c_int_is_an_error(tmp_path: Path, text: str) -> None:
    # IPOPT took <max_iterations>1e308</max_iterations> as 0 iterations (NCP wrote results from the
    # initial guess); JMP's <index>1e308 became a 300-digit folder name (OSError traceback)
    path = tmp_path / "settings.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.3">
  <NeuralControlPersonalizationTool>
    <max_iterations>{text}</max_iterations>
  </NeuralControlPersonalizationTool>
</NMSMPipelineDocument>
""")
    doc = read_settings_document(path, check_paths=False)
    with pytest.raises(InputError) as info:
        doc.integer(doc.tool_element, "max_iterations")
    assert (info.value.file, info.value.line, info.value.element) == (str(path), 3, "<max_iterations>")
    assert f"{text} is out of range (at most 2147483647 in magnitude)" in str(info.value)
    assert doc.integer(doc.tool_element, "absent", 7) == 7


def test_largest_integer_is_accepted(tmp_path: Path) -> None:
    path = tmp_path / "settings.xml"
    path.write_text('<NMSMPipelineDocument Version="1.5.3"><NeuralControlPersonalizationTool>'
                    "<max_iterations>2147483647</max_iterations></NeuralControlPersonalizationTool>"
                    "</NMSMPipelineDocument>")
    doc = read_settings_document(path, check_paths=False)
    assert doc.integer(doc.tool_element, "max_iterations") == 2**31 - 1


def test_jmp_task_index_1e308_is_one_error_and_writes_nothing(shared_data: Path, tmp_path: Path,
                                                                capsys: pytest.CaptureFixture[str]) -> None:
    folder = _copy(shared_data, "jmp/toy_simple_arm", tmp_path)
    settings = folder / "ToySettingsFile.xml"
    text = settings.read_text()
    assert text.count("<index>1</index>") == 1
    settings.write_text(text.replace("<index>1</index>", "<index>1e308</index>"))
    results = tmp_path / "results"
    assert main(["run", str(settings), "-o", str(results)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert f"{settings}:18: <index>: '1e308' is not an integer: 1e308 is out of range" in err
    assert not results.exists()


@pytest.mark.parametrize("text", ["nan", "inf", "-Infinity", "NaN"])
def test_a_number_that_is_not_finite_is_an_error(tmp_path: Path, text: str) -> None:
    # float() reads them; settings without a range check took them (GCP <belt_speed>nan, JMP
    # <allowable_error>inf: the run finished), and inf passed every "must be > 0" check
    path = tmp_path / "settings.xml"
    path.write_text(f"""<NMSMPipelineDocument Version="1.5.3">
  <GroundContactPersonalizationTool>
    <belt_speed>{text}</belt_speed>
    <translation_bounds>0.1 {text} 0.1</translation_bounds>
  </GroundContactPersonalizationTool>
</NMSMPipelineDocument>
""")
    doc = read_settings_document(path, check_paths=False)
    with pytest.raises(InputError) as info:
        doc.number(doc.tool_element, "belt_speed")
    assert (info.value.line, info.value.element) == (3, "<belt_speed>")
    assert f"'{text}' is not a number: {text} is not finite (expected a number)" in str(info.value)
    with pytest.raises(InputError) as info:
        doc.numbers(doc.tool_element, "translation_bounds", count=3)
    assert (info.value.line, info.value.element) == (4, "<translation_bounds>")
    assert f"{text} is not finite" in str(info.value)


def test_jmp_allowable_error_inf_is_one_error_and_writes_nothing(shared_data: Path, tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    folder = _copy(shared_data, "jmp/toy_simple_arm", tmp_path)
    settings = folder / "ToySettingsFile.xml"
    text = settings.read_text()
    assert text.count("<allowable_error>0.01</allowable_error>") == 1
    settings.write_text(text.replace("<allowable_error>0.01</allowable_error>",
                                     "<allowable_error>inf</allowable_error>"))
    results = tmp_path / "results"
    assert main(["run", str(settings), "-o", str(results)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert f"{settings}:11: <allowable_error>: 'inf' is not a number: inf is not finite" in err
    assert not results.exists()


def test_an_emptied_treatment_0_1_file_is_one_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # the 0.1.0 upgrade took the first child unchecked: StopIteration traceback
    path = tmp_path / "TO.xml"
    path.write_text('<?xml version="1.0"?>\n<NMSMPipelineDocument Version="0.1.0">\n  <!-- nothing yet -->\n'
                    "</NMSMPipelineDocument>\n")
    with pytest.raises(InputError) as info:
        read_settings_document(path)
    assert (info.value.file, info.value.line, info.value.element) == (str(path), 2, "<NMSMPipelineDocument>")
    assert "holds 0 elements" in str(info.value) and "<TrackingOptimizationTool>" in str(info.value)
    assert main(["run", str(path), "-o", str(tmp_path / "results")]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "TO.xml:2: <NMSMPipelineDocument>: <NMSMPipelineDocument> holds 0 elements" in err


@pytest.mark.parametrize(("folder", "name", "tool"), [
    ("treatment/toy_arm/tracking_optimization", "TorqueDrivenTOSettings.xml", "TrackingOptimizationTool"),
    ("jmp/toy_simple_arm", "ToySettingsFile.xml", "JointModelPersonalizationTool"),
])
def test_an_old_schema_file_with_two_tool_elements_is_one_error(shared_data: Path, tmp_path: Path, folder: str,
                                                               name: str, tool: str,
                                                               capsys: pytest.CaptureFixture[str]) -> None:
    # the 0.1.0 and OpenSimDocument upgrades read the first tool element and silently ignored a
    # second one (the toy-arm TO ran); a current-schema file with two is already an error
    from lxml import etree

    settings = _copy(shared_data, folder, tmp_path) / name
    tree = etree.parse(str(settings))
    first = tree.getroot().find(tool)
    first.addnext(etree.fromstring(etree.tostring(first)))
    tree.write(str(settings))
    second_line = etree.parse(str(settings)).getroot().findall(tool)[1].sourceline
    results = tmp_path / "results"
    assert main(["run", str(settings), "-o", str(results)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    root = tree.getroot().tag
    assert f"{settings}:{second_line}: <{tool}>: <{root}> holds 2 elements: <{tool}> (line " in err
    assert f"(expected exactly one tool element in <{root}>" in err
    assert not results.exists()


def test_a_second_term_set_in_one_block_is_one_error(shared_data: Path, tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    # every <RCNLCostTermSet> of a block whose set is optional (MTLI, synergy extrapolation) was
    # read: a copied set counted each of its terms twice (the MTP tutorial ran with the length
    # initialization's terms doubled); a task's required set already refused a second one
    from lxml import etree

    folder = _copy(shared_data, "mtp/uf_subject3_tutorial", tmp_path)
    settings = folder / "CompletedSettingsFiles" / "MTPSettingsV1.xml"
    tree = etree.parse(str(settings))
    task_set = tree.getroot().find("MuscleTendonPersonalizationTool/MuscleTendonLengthInitialization/RCNLCostTermSet")
    first_line = task_set.sourceline
    task_set.addnext(etree.fromstring(etree.tostring(task_set)))
    tree.write(str(settings))
    second_line = etree.parse(str(settings)).getroot().findall(
        "MuscleTendonPersonalizationTool/MuscleTendonLengthInitialization/RCNLCostTermSet")[1].sourceline
    results = tmp_path / "results"
    assert main(["--progress", "0", "run", str(settings), "-o", str(results)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert (f"{settings}:{second_line}: <RCNLCostTermSet>: <RCNLCostTermSet> appears 2 times in "
            f"<MuscleTendonLengthInitialization> (first at line {first_line}) (expected one <RCNLCostTermSet>)") in err
    assert not results.exists()

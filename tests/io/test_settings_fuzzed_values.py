"""Settings values found by the fuzz audit of the shared settings files (one element changed at a
time): each is one clear InputError naming the file, the element and what was expected, before
anything runs or is written."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.settings.document import read_settings_document


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

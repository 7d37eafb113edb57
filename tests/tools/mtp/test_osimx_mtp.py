"""MTP with an input ``.osimx``: a misspelled field warns, a muscle the model lacks is an error.

The tutorial's MTP settings V3 (subject 3, reduced-muscle model) with NCP's copy of MTP's
``UF_Subject_3_reduced_muscles_mtp.osimx`` as ``<input_osimx_file>``; ``prepare`` reads
everything a run needs (a few seconds) and applies the ``.osimx`` to the model.
"""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.osimx import read_osimx
from nmsm.model import load_model
from nmsm.tools.mtp.model_info import muscle_parameters
from nmsm.tools.mtp.run import prepare

OSIMX = "ncp/uf_subject3_tutorial/mtpResults/UF_Subject_3_reduced_muscles_mtp.osimx"


@pytest.fixture
def folder(shared_data: Path, tmp_path: Path) -> Path:
    """A writable copy of the MTP tutorial with the input ``.osimx`` next to settings V3."""
    copy = tmp_path / "mtp"
    shutil.copytree(shared_data / "mtp" / "uf_subject3_tutorial", copy)
    shutil.copy(shared_data / OSIMX, copy / "CompletedSettingsFiles" / "input.osimx")
    return copy


def _settings(folder: Path, change: tuple[str, str] | None = None) -> Path:
    """Settings V3 reading ``input.osimx``, with ``change`` (old, new) applied to the first matching line."""
    osimx = folder / "CompletedSettingsFiles" / "input.osimx"
    if change is not None:
        lines = osimx.read_text().splitlines(keepends=True)
        index = next(i for i, line in enumerate(lines) if change[0] in line)
        lines[index] = lines[index].replace(change[0], change[1])
        osimx.write_text("".join(lines))
    settings = folder / "CompletedSettingsFiles" / "MTPSettingsV3.xml"
    text = settings.read_text().replace("<input_osimx_file/>", "<input_osimx_file>input.osimx</input_osimx_file>")
    settings.write_text(text)
    return settings


def _prepare(settings: Path):
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        setup = prepare(settings)
    return setup, [str(w.message) for w in record if ".osimx" in str(w.message)]


def test_correct_osimx_is_applied_without_warnings(folder: Path) -> None:
    setup, messages = _prepare(_settings(folder))
    assert messages == []
    muscles = setup.data.muscles
    expected = read_osimx(folder / "CompletedSettingsFiles" / "input.osimx").muscles["bflh_r"].tendon_slack_length
    assert muscles.tendon_slack_length[list(muscles.names).index("bflh_r")] == expected


def test_misspelled_parameter_warns_with_file_line_and_close_match(folder: Path) -> None:
    settings = _settings(folder, ("tendon_slack_length>", "tendon_slack_lenght>"))
    osimx = folder / "CompletedSettingsFiles" / "input.osimx"
    line = next(i for i, text in enumerate(osimx.read_text().splitlines(), start=1) if "tendon_slack_lenght" in text)
    setup, messages = _prepare(settings)
    (message,) = messages
    assert message.startswith(f"{osimx}:{line}: unknown element <tendon_slack_lenght>")
    assert '<RCNLMuscle name="bflh_r">' in message and "did you mean <tendon_slack_length>?" in message
    model_value = load_model(folder / "UF_Subject_3_reduced_muscles.osim").muscle("bflh_r").tendon_slack_length
    muscles = setup.data.muscles
    assert muscles.tendon_slack_length[list(muscles.names).index("bflh_r")] == model_value  # misspelled: not used


def test_muscle_not_in_model_is_an_error(folder: Path) -> None:
    settings = _settings(folder, ('name="bflh_r"', 'name="bflh_rr"'))
    with pytest.raises(InputError) as info:
        prepare(settings)
    error = info.value
    assert error.file is not None and Path(error.file).name == "input.osimx" and error.line == 7
    assert error.element == '<RCNLMuscle name="bflh_rr">'
    assert "muscle 'bflh_rr' is not in the model" in str(error) and "did you mean 'bflh_r'" in str(error)
    assert "UF_Subject_3_reduced_muscles.osim" in str(error) and "muscles of the model: bflh_r, bfsh_r" in str(error)


def test_osimx_with_a_subset_of_the_model_muscles_is_fine(shared_data: Path, tmp_path: Path) -> None:
    """MTP's muscles are those crossing the coordinates; an .osimx may hold fewer or other model muscles."""
    model = load_model(shared_data / "mtp" / "uf_subject3_tutorial" / "UF_Subject_3_reduced_muscles.osim")
    osimx = read_osimx(shared_data / OSIMX)
    parameters = muscle_parameters(model, ["soleus_r"], osimx)
    assert parameters.tendon_slack_length[0] == osimx.muscles["soleus_r"].tendon_slack_length

"""NCP with an input ``.osimx``: a misspelled muscle set warns, a muscle the model lacks is an error.

The tutorial's NCP settings V1 (subject 3) on a writable copy; ``load_ncp`` reads the model,
the data and MTP's ``.osimx`` and applies its muscle parameters (about a second).
"""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.osimx import read_osimx
from nmsm.tools.ncp.loading import load_ncp
from nmsm.tools.ncp.run import read_settings

OSIMX = Path("mtpResults") / "UF_Subject_3_reduced_muscles_mtp.osimx"


@pytest.fixture
def folder(shared_data: Path, tmp_path: Path) -> Path:
    copy = tmp_path / "ncp"
    shutil.copytree(shared_data / "ncp" / "uf_subject3_tutorial", copy)
    return copy


def _load(folder: Path):
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        setup = load_ncp(read_settings(folder / "CompletedSettingsFiles" / "NCPSettingsV1.xml"))
    return setup, [str(w.message) for w in record if ".osimx" in str(w.message)]


def test_correct_osimx_is_applied_without_warnings(folder: Path) -> None:
    setup, messages = _load(folder)
    assert messages == []
    muscles = setup.inputs.muscles
    i = list(muscles.names).index("bflh_r")
    assert muscles.max_isometric_force[i] == read_osimx(folder / OSIMX).muscles["bflh_r"].max_isometric_force


def test_misspelled_muscle_set_warns_with_file_line_and_close_match(folder: Path) -> None:
    """The audit's P1: a misspelled <RCNLMuscleSet> silently ran NCP on the generic model parameters."""
    path = folder / OSIMX
    path.write_text(path.read_text().replace("RCNLMuscleSet>", "RCNLMusclesSet>"))
    line = next(i for i, text in enumerate(path.read_text().splitlines(), start=1) if "<RCNLMusclesSet>" in text)
    _, messages = _load(folder)
    (message,) = messages
    assert message.startswith(f"{path}:{line}: unknown element <RCNLMusclesSet>")
    assert '<OsimxModel name="UF_Subject_3_reduced_muscles">' in message
    assert "did you mean <RCNLMuscleSet>?" in message


def test_muscle_not_in_model_is_an_error(folder: Path) -> None:
    path = folder / OSIMX
    path.write_text(path.read_text().replace('name="soleus_r"', 'name="soleus_rr"'))
    line = next(i for i, text in enumerate(path.read_text().splitlines(), start=1) if 'name="soleus_rr"' in text)
    with pytest.raises(InputError) as info:
        _load(folder)
    error = info.value
    assert error.file == str(path) and error.line == line and error.element == '<RCNLMuscle name="soleus_rr">'
    assert "muscle 'soleus_rr' is not in the model" in str(error) and "did you mean 'soleus_r'?" in str(error)
    assert "expected RCNLMuscle names that are muscles of the model" in str(error)

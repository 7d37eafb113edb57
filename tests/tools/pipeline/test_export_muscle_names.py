"""``nmsm export`` of an ``<RCNLMuscle>`` naming no muscle of the model (fuzz audit of .osimx
files). An entry holding a value OpenSim can hold (optimal fiber length, ...) was refused, but
one holding only delays, activation constants or EMG scales (the original's 2023 MTP files
hold no lengths) was exported silently and counted in the note about what OpenSim cannot
hold. Now every such entry is one error naming the .osimx, its line, close matches and the
model's muscles, and nothing is written."""

from __future__ import annotations

import re

import pytest

from nmsm.cli import main

PATIENT3 = ("ncp", "patient3_bilateral_trials1to3")


@pytest.mark.parametrize(("name", "hint"), [("addbrev_rr", "did you mean 'addbrev_r'"), ("no_such_muscle", "")])
def test_an_unknown_muscle_without_exportable_values_is_one_error(shared_data, tmp_path, capsys, name, hint) -> None:
    folder = shared_data.joinpath(*PATIENT3)
    text = (folder / "mtpResults" / "model.osimx").read_text(encoding="utf-8")
    text, count = re.subn(r'<RCNLMuscle name="addbrev_r">', f'<RCNLMuscle name="{name}">', text, count=1)
    assert count == 1 and "<optimal_fiber_length>" not in text  # delays, activation, EMG scales only
    osimx = tmp_path / "renamed.osimx"
    osimx.write_text(text, encoding="utf-8")
    line = next(i for i, t in enumerate(text.splitlines(), start=1) if f'name="{name}"' in t)
    output = tmp_path / "exported.osim"
    with pytest.warns(UserWarning):  # the 2023 layout's own warnings
        code = main(["export", str(osimx), "--model", str(folder / "model.osim"), "-o", str(output)])
    err = capsys.readouterr().err
    assert code != 0 and "Traceback" not in err
    assert f"{osimx}:{line}: <RCNLMuscle name=\"{name}\">: muscle '{name}' is not in the model" in err and hint in err
    assert not output.exists()

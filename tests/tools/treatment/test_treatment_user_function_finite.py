"""A user function's numeric option (DO's <target_speed>) that is nan or inf is one error at its
term's line before anything is solved or written (fuzz audit: float() read 'inf', and IPOPT stopped with
Invalid_Number_Detected after 0 iterations, leaving a last_iterate folder in the results)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from nmsm.cli import main


@pytest.mark.parametrize("text", ["inf", "nan"])
def test_target_speed_not_finite_is_one_error_and_writes_nothing(shared_data: Path, tmp_path: Path, text: str,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "torque_kick_tutorial"
    shutil.copytree(shared_data / "treatment" / "torque_kick_tutorial", folder)
    settings = folder / "CompletedSettingsFiles" / "TorqueDOSettingsV4.xml"
    lines = settings.read_text().splitlines(keepends=True)
    assert lines[38].strip() == "<target_speed>14.35</target_speed>"
    lines[38] = lines[38].replace("14.35", text)
    settings.write_text("".join(lines))
    results = tmp_path / "results"
    assert main(["--progress", "0", "run", str(settings), "-o", str(results)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "IPOPT" not in err
    # the line of the term (as for an option that is no number at all), the option named
    assert (f"{settings}:33: <target_speed>: term 'user_defined' (User defined): <target_speed> = '{text}' is not "
            "finite (expected a finite number)") in err
    assert not results.exists()

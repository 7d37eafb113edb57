"""Operating-system errors end in the project's error naming the path and what to do, not a
traceback: a file or folder name longer than 255 bytes (in a settings file or on the command
line) and a full disk while ``nmsm run`` writes results (nothing half-written is left)."""

from __future__ import annotations

import errno
import shutil
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError

TOY = "jmp/toy_simple_arm"
LONG = "a" * 300


@pytest.fixture
def toy(shared_data: Path, tmp_path: Path) -> Path:
    """A copy of the toy JMP settings with its model and markers."""
    folder = tmp_path / "toy"
    folder.mkdir()
    for name in ("ToySettingsFile.xml", "simple_arm_translated_away.osim", "simple_arm.trc"):
        shutil.copy(shared_data / TOY / name, folder / name)
    return folder / "ToySettingsFile.xml"


def test_a_long_name_in_a_settings_file(toy: Path) -> None:
    from nmsm.tools.jmp.run import read_settings

    text = toy.read_text()
    toy.write_text(text.replace("simple_arm_translated_away.osim", f"{LONG}.osim", 1))
    with pytest.raises(InputError) as caught:
        read_settings(toy)
    message = str(caught.value)
    assert message.startswith(f"{toy}:") and "<input_model_file>" in message and "at most 255 bytes" in message


@pytest.mark.parametrize("where", ["results", "settings"])
def test_a_long_name_on_the_command_line(toy: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                         where: str) -> None:
    settings = str(toy) if where == "results" else str(tmp_path / f"{LONG}.xml")
    out = tmp_path / LONG / "out" if where == "results" else tmp_path / "out"
    assert main(["run", settings, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("nmsm: error: ") and "Traceback" not in err and "a" * 40 in err
    assert "255 bytes" in err or "File name too long" in err


def _full_disk(*args: object, **kwargs: object) -> None:
    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_full_disk_during_nmsm_run_leaves_nothing(toy: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                     capsys: pytest.CaptureFixture[str]) -> None:
    import nmsm.tools.jmp.run as jmp_run

    monkeypatch.setattr(jmp_run, "write_storage", _full_disk)
    out = tmp_path / "results"
    assert main(["run", str(toy), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert f"nmsm: error: {out}: No space left on device (expected free space" in err
    assert not out.exists()


def test_a_full_disk_while_mtp_writes_leaves_the_earlier_results(shared_data: Path, tmp_path: Path,
                                                                 monkeypatch: pytest.MonkeyPatch,
                                                                 capsys: pytest.CaptureFixture[str]) -> None:
    from tests.tools.mtp.test_mtp_bad_input import write_settings

    import nmsm.tools.mtp.outputs as mtp_outputs

    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    shutil.copytree(tutorial / "preprocessed", tmp_path / "preprocessed")
    settings = write_settings(tmp_path, tutorial)
    out = tmp_path / "results"
    out.mkdir()
    (out / "earlier.txt").write_text("kept")
    real = mtp_outputs.osimx_file

    def full_after_some_files(stage: Path, *args: object, **kwargs: object) -> None:
        real(stage, *args, **kwargs)
        raise OSError(errno.ENOSPC, "No space left on device", str(stage / "Analysis" / "x.sto"))

    monkeypatch.setattr(mtp_outputs, "osimx_file", full_after_some_files)
    assert main(["run", str(settings), "-o", str(out), "--accept-unconverged"]) == 1  # a short run: the results
    assert "No space left on device" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["earlier.txt"]

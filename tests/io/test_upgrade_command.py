"""``nmsm upgrade-settings`` and ``nmsm print-xml -o``: where they may write.

The output's folder must exist and the output must not be a folder (clear errors, no
traceback); an existing output is replaced only with ``--force``; the old settings file (in
any link form) and the files it names are never replaced; the file is written atomically.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.io.settings import read_tool_settings
from nmsm.io.settings.upgrade import upgrade_settings_file

OLD_TO = "treatment/toy_arm/tracking_optimization"


@pytest.fixture()
def toy(shared_data: Path, tmp_path: Path) -> Path:
    """A writable copy of the toy arm's 0.1.0 tracking-optimization folder."""
    folder = tmp_path / "toy"
    shutil.copytree(shared_data / OLD_TO, folder)
    for path in [folder, *folder.rglob("*")]:
        path.chmod(path.stat().st_mode | 0o200)
    return folder


def _digests(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.is_symlink()}


def _fails(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(args) == 1
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and captured.err.startswith("nmsm: error: ")
    return captured.err


def test_missing_output_folder_or_a_folder_is_a_clear_error(
    toy: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(toy)
    before = _digests(toy)
    err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "nodir/sub/new.xml"], capsys)
    assert "nodir/sub/new.xml: cannot write the output file: its folder nodir/sub does not exist" in err
    err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "preprocessed"], capsys)
    assert "preprocessed: -o names a folder, not a file" in err and "e.g. preprocessed/" in err
    err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "simple_arm.osim/new.xml"], capsys)
    assert "simple_arm.osim is a file, not a folder" in err
    err = _fails(["print-xml", "to", "-o", "nodir/x.xml"], capsys)
    assert "nodir/x.xml: cannot write the output file: its folder nodir does not exist" in err
    err = _fails(["print-xml", "to", "-o", "preprocessed"], capsys)
    assert "preprocessed: -o names a folder" in err
    assert not (toy / "nodir").exists() and _digests(toy) == before


def test_the_old_file_is_never_overwritten_in_any_link_form(
    toy: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(toy)
    old = toy / "TorqueDrivenTOSettings.xml"
    os.link(old, toy / "hard.xml")
    (toy / "soft.xml").symlink_to(old.name)
    before = _digests(toy)
    for output in ("TorqueDrivenTOSettings.xml", "./TorqueDrivenTOSettings.xml", str(old), "hard.xml", "soft.xml",
                   "preprocessed/../TorqueDrivenTOSettings.xml"):
        for force in ([], ["--force"]):
            err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", output, *force], capsys)
            assert "the output file is the settings file being upgraded" in err and "would overwrite" in err
    assert _digests(toy) == before and (toy / "soft.xml").is_symlink()


def test_files_and_data_the_old_file_names_are_never_overwritten(
    toy: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(toy)
    before = _digests(toy)
    for force in ([], ["--force"]):
        err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "gpopsSettings.xml", *force], capsys)
        assert ("gpopsSettings.xml: the output file is the file TorqueDrivenTOSettings.xml names in "
                "<optimal_control_settings_file> (line 23): writing it would overwrite an input") in err
        err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "simple_arm.osim", *force], capsys)
        assert "names in <input_model_file>" in err
    # the IK file the upgrader reads (the trial's states) is inside the data folder the settings name
    err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "preprocessed/IKData/arm1.sto",
                  "--force"], capsys)
    assert "already exists inside the folder TorqueDrivenTOSettings.xml names in <data_directory>" in err
    assert _digests(toy) == before
    with pytest.raises(InputError, match="would overwrite an input"):
        upgrade_settings_file(toy / "TorqueDrivenTOSettings.xml", toy / "gpopsSettings.xml", force=True)


def test_an_existing_output_is_replaced_only_with_force(
    toy: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(toy)
    notes = toy / "notes.xml"
    notes.write_text("my notes\n")
    err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "notes.xml"], capsys)
    assert "notes.xml: the output file already exists (expected a new file name, or --force to replace it)" in err
    assert notes.read_text() == "my notes\n"
    assert main(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "notes.xml", "--force"]) == 0
    assert "wrote notes.xml (replaced the existing file: --force)" in capsys.readouterr().err
    assert read_tool_settings(notes, check_paths=False).trial_name == "arm1"
    # print-xml over a filled-in settings file
    settings = toy / "TO.xml"
    shutil.copy(notes, settings)
    filled = settings.read_bytes()
    err = _fails(["print-xml", "to", "-o", "TO.xml"], capsys)
    assert "TO.xml: the output file already exists" in err and settings.read_bytes() == filled
    assert main(["print-xml", "to", "-o", "TO.xml", "--force"]) == 0
    assert "<TrackingOptimizationTool>" in settings.read_text() and "replaced" in capsys.readouterr().err


def test_a_failed_write_leaves_the_earlier_file(
    toy: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(toy)
    out = toy / "new.xml"
    out.write_text("earlier\n")

    def broken_fsync(fd: int) -> None:
        raise OSError(28, "No space left on device")

    monkeypatch.setattr("nmsm.io.output_file.os.fsync", broken_fsync)
    err = _fails(["upgrade-settings", "TorqueDrivenTOSettings.xml", "-o", "new.xml", "--force"], capsys)
    assert "new.xml: cannot write the output file: No space left on device" in err
    err = _fails(["print-xml", "solver", "-o", "new.xml", "--force"], capsys)
    assert "No space left on device" in err
    assert out.read_text() == "earlier\n"
    assert sorted(p.name for p in toy.iterdir() if p.name.startswith(".")) == []  # no temporary file left

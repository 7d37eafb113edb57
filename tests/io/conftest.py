"""Fixtures of the reader tests."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest


@pytest.fixture
def arm(shared_data: Path, tmp_path: Path) -> Path:
    """A writable copy of the toy arm JMP tutorial folder (``../shared/data/jmp/toy_simple_arm``)."""
    folder = tmp_path / "arm"
    shutil.copytree(shared_data / "jmp" / "toy_simple_arm", folder)
    for path in folder.iterdir():
        path.chmod(0o644)
    return folder

"""Fixtures shared by the MTP test modules."""

from __future__ import annotations

import shutil

import pytest


@pytest.fixture
def case(tmp_path, shared_data):
    """(folder, tutorial): a writable copy of subject 3's preprocessed MTP data in ``folder``
    and the shared tutorial folder (its model and passive data are read from there)."""
    tutorial = shared_data / "mtp" / "uf_subject3_tutorial"
    shutil.copytree(tutorial / "preprocessed", tmp_path / "preprocessed")
    return tmp_path, tutorial

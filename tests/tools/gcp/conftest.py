"""Fixtures of the GCP tests: the tutorial (``gcp/uf_subject3_tutorial``) paths and a
synthetic known-answer case written once per session."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def tutorial(shared_data: Path) -> Path:
    return shared_data / "gcp" / "uf_subject3_tutorial"


@pytest.fixture(scope="session")
def synthetic_case(tmp_path_factory: pytest.TempPathFactory):
    from nmsm.examples.synthetic_gcp import write_synthetic_gcp

    return write_synthetic_gcp(tmp_path_factory.mktemp("synthetic_gcp"))

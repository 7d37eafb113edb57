"""Fixtures of the model-core tests (helpers are in ``model_testing.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def model_cache():
    """Parsed models and their CasadiModels, shared by the tests of a session."""
    from nmsm.model import CasadiModel, load_model

    cache: dict[str, tuple] = {}

    def get(path: Path):
        key = str(path)
        if key not in cache:
            model = load_model(path)
            cache[key] = (model, CasadiModel(model))
        return cache[key]

    return get

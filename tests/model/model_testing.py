"""Helpers for the model-core tests: the shared model files and random poses.

``MODEL_FILES`` lists every ``.osim`` under the shared data (relative paths; empty when the
data are absent, in which case the parametrized tests are skipped through ``shared_data``).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

SHARED = Path(os.environ.get("NMSM_SHARED_DATA") or Path(__file__).resolve().parents[2].parent / "shared" / "data")
MODEL_FILES = sorted(str(p.relative_to(SHARED)) for p in SHARED.rglob("*.osim")) if SHARED.is_dir() else []
#: the number of models the shared data README promises
EXPECTED_MODEL_COUNT = 35


def random_poses(model, casadi_model, count: int, rng: np.random.Generator) -> np.ndarray:
    """``(count, n)`` coordinates uniformly within each range (clipped to [-pi, pi]),
    dependent coordinates computed through their couplers."""
    lo = np.array([max(c.range[0], -np.pi) for c in model.coordinates])
    hi = np.array([min(c.range[1], np.pi) for c in model.coordinates])
    q = lo + (hi - lo) * rng.random((count, len(model.coordinates)))
    return casadi_model.coordinates.dependent_values(q)

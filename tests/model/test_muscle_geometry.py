"""The muscle-geometry provider: exact paths for path-point muscles, surrogates for wrapping ones."""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.errors import ModelError
from nmsm.model import load_model
from nmsm.model.muscle_geometry import MuscleGeometry
from nmsm.model.muscle_paths import PathMuscleGeometry, evaluate_function
from nmsm.model.surrogate import fit_surrogate_model
from nmsm.model.surrogate_data import read_samples

KICK = "treatment/surrogate_kick_tutorial"
COORDINATES = ["hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r",
               "subtalar_angle_r"]


@pytest.fixture(scope="module")
def kick(shared_data):
    model = load_model(shared_data / KICK / "RightLegAndPelvis.osim")
    rotational = {c.name for c in model.coordinates if c.is_rotational}
    samples = read_samples(shared_data / KICK / "surrogateData", COORDINATES, rotational)
    return model, fit_surrogate_model(samples, 4, 1e-4, holdout_fraction=0.0)


def test_sources_and_values(kick) -> None:
    model, surrogate = kick
    geometry = MuscleGeometry(model, None, COORDINATES, surrogate=surrogate)
    assert geometry.sources == {"bflh_r": "path", "bfsh_r": "surrogate", "gasmed_r": "surrogate",
                                "glmax2_r": "surrogate", "iliacus_r": "surrogate", "recfem_r": "surrogate",
                                "soleus_r": "path", "tibant_r": "path", "vasmed_r": "surrogate"}
    rng = np.random.default_rng(0)
    q = np.tile([c.default_value for c in model.coordinates], (6, 1))
    idx = [model.coordinate_index(c) for c in COORDINATES]
    q[:, idx] = rng.uniform(-0.3, 0.8, (6, len(idx)))
    qdot = rng.normal(size=q.shape)
    lengths, velocities, arms = evaluate_function(geometry.function(), q, qdot)
    exact = PathMuscleGeometry(model, muscles=["bflh_r", "soleus_r", "tibant_r"], coordinates=COORDINATES)
    e_lengths, e_velocities, e_arms = evaluate_function(exact.function(), q, qdot)
    rows = [geometry.muscles.index(m) for m in exact.muscles]
    np.testing.assert_allclose(lengths[:, rows], e_lengths, atol=1e-15)
    np.testing.assert_allclose(arms[:, rows], e_arms, atol=1e-15)
    np.testing.assert_allclose(velocities[:, rows], e_velocities, atol=1e-15)
    sur = surrogate.evaluate(q[:, idx], qdot[:, idx], coordinates=COORDINATES, muscles=["gasmed_r", "iliacus_r"])
    rows = [geometry.muscles.index(m) for m in ("gasmed_r", "iliacus_r")]
    np.testing.assert_allclose(lengths[:, rows], sur.lengths, atol=1e-14)
    np.testing.assert_allclose(arms[:, rows], sur.moment_arms, atol=1e-14)
    np.testing.assert_allclose(velocities[:, rows], sur.velocities, atol=1e-14)


def test_prefer_surrogate_and_missing_surrogate(kick) -> None:
    model, surrogate = kick
    assert set(MuscleGeometry(model, surrogate=surrogate, prefer_surrogate=True).sources.values()) == {"surrogate"}
    with pytest.raises(ModelError, match="gasmed_r"):
        MuscleGeometry(model, ["soleus_r", "gasmed_r"])
    only_paths = MuscleGeometry(model, ["soleus_r", "bflh_r"])
    assert only_paths.function().size_out(2) == (2, len(model.independent_coordinate_names))

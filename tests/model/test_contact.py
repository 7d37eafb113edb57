"""SmoothSphereHalfSpaceForce (the 2D Moco model's foot contacts) against OpenSim."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np


def _states(model, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    names = model.coordinate_names
    q = rng.uniform(-0.3, 0.3, (count, len(names)))
    q[:, names.index("pelvis_ty")] = rng.uniform(0.85, 0.95, count)  # feet around the floor
    q[:, names.index("pelvis_tx")] = rng.uniform(-1, 1, count)
    return q, rng.normal(0, 0.5, q.shape)


def test_contact_forces_match_opensim(shared_data: Path, bridge, model_cache) -> None:
    model, cm = model_cache(shared_data / "moco2d" / "2D_gait.osim")
    q, u = _states(model, 25, np.random.default_rng(21))
    ref = bridge.call("oracle_contact_forces", path=model.source_file, q=q, u=u)
    assert ref["names"] == [f.name for f in model.contact_forces]
    assert ref["constant_contact_force"] == [f.constant_contact_force for f in model.contact_forces]
    assert (np.abs(ref["forces"]).max(axis=2) > 10.0).sum() >= 20  # real contact, not only the smoothing tails
    assert _largest_error(model, cm, q, u, ref) <= 1e-8 * max(1.0, np.abs(ref["forces"]).max())


def test_smooth_sphere_stribeck_friction_matches_opensim(shared_data: Path, bridge, tmp_path: Path) -> None:
    """The 2D model's spheres have equal static and dynamic friction (0.8), so the Stribeck term
    ``2 (mu_s - mu_d) / (1 + v_r^2)`` is zero above; here mu_s = 1.2 > mu_d = 0.6 (found by
    mutation testing: the term was unchecked)."""
    from nmsm.model import CasadiModel, load_model

    original = shared_data / "moco2d" / "2D_gait.osim"
    text = original.read_text(encoding="utf-8")
    text, n_static = re.subn(r"<static_friction>[^<]*</static_friction>", "<static_friction>1.2</static_friction>", text)
    text, n_dynamic = re.subn(r"<dynamic_friction>[^<]*</dynamic_friction>", "<dynamic_friction>0.6</dynamic_friction>",
                              text)
    assert n_static == n_dynamic == 4
    path = tmp_path / "2D_gait_stribeck.osim"
    path.write_text(text, encoding="utf-8")
    model = load_model(path)
    assert {(f.static_friction, f.dynamic_friction) for f in model.contact_forces} == {(1.2, 0.6)}
    q, u = _states(model, 25, np.random.default_rng(23))
    ref = bridge.call("oracle_contact_forces", path=str(path), q=q, u=u)
    plain = bridge.call("oracle_contact_forces", path=str(original), q=q, u=u)
    # the sample reaches the Stribeck regime: OpenSim's forces change by tens of newtons
    assert np.abs(ref["forces"] - plain["forces"]).max() > 20.0
    assert _largest_error(model, CasadiModel(model), q, u, ref) <= 1e-8 * max(1.0, np.abs(ref["forces"]).max())


def _largest_error(model, cm, q: np.ndarray, u: np.ndarray, ref: dict) -> float:
    """Largest difference (N, N·m) of our element forces and their torques about the sphere
    bodies' origins from OpenSim's ``oracle_contact_forces`` at the states ``q``, ``u``."""
    function = cm.contact_force_function()
    worst = 0.0
    for i in range(len(q)):
        forces, points = (np.array(v) for v in function(q[i], u[i]))
        for j, element in enumerate(model.contact_forces):
            body = model.contact_geometry[element.sphere].body
            origin = np.array(cm.body_pose(body, q[i])[1]).ravel()
            torque = np.cross(points[:, j] - origin, forces[:, j])
            worst = max(worst, np.abs(forces[:, j] - ref["forces"][i, j]).max(),
                        np.abs(torque - ref["torques"][i, j]).max())
    return worst


def test_inverse_dynamics_with_contact_matches_opensim(shared_data: Path, bridge, model_cache) -> None:
    model, cm = model_cache(shared_data / "moco2d" / "2D_gait.osim")
    rng = np.random.default_rng(22)
    q, u = _states(model, 8, rng)
    udot = rng.normal(0, 3, q.shape)
    ref = bridge.call("oracle_inverse_dynamics", path=model.source_file, q=q, u=u, udot=udot, forces="no_muscles")
    ours = np.array(cm.inverse_dynamics_function(include_contact=True).map(len(q))(q.T, u.T, udot.T)).T
    assert np.abs(ours - ref).max() <= 1e-6
    without = np.array(cm.inverse_dynamics_function().map(len(q))(q.T, u.T, udot.T)).T
    assert np.abs(without - ref).max() > 1.0  # contact matters in these states

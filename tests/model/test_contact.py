"""SmoothSphereHalfSpaceForce (the 2D Moco model's foot contacts) against OpenSim."""

from __future__ import annotations

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
    function = cm.contact_force_function()
    worst = 0.0
    in_contact = 0
    for i in range(len(q)):
        forces, points = (np.array(v) for v in function(q[i], u[i]))
        for j, element in enumerate(model.contact_forces):
            body = model.contact_geometry[element.sphere].body
            origin = np.array(cm.body_pose(body, q[i])[1]).ravel()
            torque = np.cross(points[:, j] - origin, forces[:, j])
            worst = max(worst, np.abs(forces[:, j] - ref["forces"][i, j]).max(),
                        np.abs(torque - ref["torques"][i, j]).max())
            in_contact += np.abs(ref["forces"][i, j]).max() > 10.0
    assert in_contact >= 20  # the sample exercises real contact, not only the smoothing tails
    assert worst <= 1e-8 * max(1.0, np.abs(ref["forces"]).max())


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

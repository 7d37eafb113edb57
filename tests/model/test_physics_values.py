"""Contact physics the existing comparisons do not reach (found by mutation testing).

The 2D Moco gait model's SmoothSphereHalfSpaceForces have equal static and dynamic
friction (0.8), so the Stribeck term ``2 (mu_s - mu_d) / (1 + v_r^2)`` of
:mod:`nmsm.model.contact_smooth_sphere` is zero in ``test_contact.py``. Here the same model
with mu_s = 1.2 > mu_d = 0.6 is compared with OpenSim through the bridge.
"""

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


def test_smooth_sphere_stribeck_friction_matches_opensim(shared_data: Path, bridge, tmp_path: Path) -> None:
    from nmsm.model import CasadiModel, load_model

    original = shared_data / "moco2d" / "2D_gait.osim"
    text = original.read_text()
    text, n_static = re.subn(r"<static_friction>[^<]*</static_friction>", "<static_friction>1.2</static_friction>", text)
    text, n_dynamic = re.subn(r"<dynamic_friction>[^<]*</dynamic_friction>", "<dynamic_friction>0.6</dynamic_friction>",
                              text)
    assert n_static == n_dynamic == 4
    path = tmp_path / "2D_gait_stribeck.osim"
    path.write_text(text)
    model = load_model(path)
    assert {(f.static_friction, f.dynamic_friction) for f in model.contact_forces} == {(1.2, 0.6)}
    cm = CasadiModel(model)
    q, u = _states(model, 25, np.random.default_rng(23))
    ref = bridge.call("oracle_contact_forces", path=str(path), q=q, u=u)
    plain = bridge.call("oracle_contact_forces", path=str(original), q=q, u=u)
    # the sample reaches the Stribeck regime: OpenSim's forces change by tens of newtons
    assert np.abs(ref["forces"] - plain["forces"]).max() > 20.0
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
    assert worst <= 1e-8 * max(1.0, np.abs(ref["forces"]).max())

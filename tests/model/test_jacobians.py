"""CasADi's exact derivatives against central finite differences."""

from __future__ import annotations

from pathlib import Path

import casadi as cs
import numpy as np
from model_testing import random_poses


def _central_difference(f, x: np.ndarray, h: float) -> np.ndarray:
    columns = []
    for j in range(x.size):
        e = np.zeros_like(x)
        e[j] = h
        columns.append((np.asarray(f(x + e)).ravel(order="F") - np.asarray(f(x - e)).ravel(order="F")) / (2 * h))
    return np.stack(columns, axis=1)


def test_inverse_dynamics_jacobian(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    rng = np.random.default_rng(31)
    q = random_poses(model, cm, 1, rng)[0]
    x0 = np.concatenate([q, rng.normal(size=cm.n), rng.normal(size=cm.n)])
    loads = np.concatenate([rng.normal(0, 300, 3), rng.normal(0, 0.5, 3), rng.normal(0, 10, 3)])
    f = cm.inverse_dynamics_function(["calcn_r"])
    x = cs.SX.sym("x", 3 * cm.n)
    tau = f(x[: cm.n], x[cm.n: 2 * cm.n], x[2 * cm.n:], loads)
    jacobian = np.array(cs.Function("j", [x], [cs.jacobian(tau, x)])(x0))
    numeric = _central_difference(lambda v: f(v[: cm.n], v[cm.n: 2 * cm.n], v[2 * cm.n:], loads), x0, 1e-6)
    scale = np.abs(jacobian).max()
    assert np.abs(jacobian - numeric).max() <= 1e-6 * scale


def test_contact_inverse_dynamics_jacobian(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "moco2d" / "2D_gait.osim")
    rng = np.random.default_rng(32)
    q = rng.uniform(-0.2, 0.2, cm.n)
    q[model.coordinate_index("pelvis_ty")] = 0.9
    x0 = np.concatenate([q, rng.normal(0, 0.3, cm.n), rng.normal(size=cm.n)])
    f = cm.inverse_dynamics_function(include_contact=True)
    x = cs.SX.sym("x", 3 * cm.n)
    tau = f(x[: cm.n], x[cm.n: 2 * cm.n], x[2 * cm.n:])
    jacobian = np.array(cs.Function("j", [x], [cs.jacobian(tau, x)])(x0))
    numeric = _central_difference(lambda v: f(v[: cm.n], v[cm.n: 2 * cm.n], v[2 * cm.n:]), x0, 1e-7)
    assert np.abs(jacobian - numeric).max() <= 1e-5 * np.abs(jacobian).max()


def test_marker_jacobian_wrt_coordinates_and_parameters(shared_data: Path) -> None:
    from nmsm.model import CasadiModel, ModelParameters, load_model

    model = load_model(shared_data / "models" / "RCNL2024.osim")
    params = ModelParameters(model)
    params.joint_frame_orientation("knee_r", "parent")
    params.joint_frame_translation("knee_r", "child", components=(0, 2))
    params.joint_frame_orientation("ankle_r", "child", components=(1,))
    params.marker_location(model.markers[0].name)
    params.body_scale("pelvis")
    params.body_scale("tibia_r")
    cm = CasadiModel(model, params)
    rng = np.random.default_rng(33)
    q0 = random_poses(model, cm, 1, rng)[0]
    p0 = params.initial_values + rng.normal(0, 0.02, params.size)
    f = cm.marker_function()
    q = cs.SX.sym("q", cm.n)
    p = cs.SX.sym("p", params.size)
    out = cs.vec(f(q, p))
    jac = cs.Function("j", [q, p], [cs.jacobian(out, q), cs.jacobian(out, p)])
    jq, jp = (np.array(m) for m in jac(q0, p0))
    nq = _central_difference(lambda v: f(v, p0), q0, 1e-6)
    np_ = _central_difference(lambda v: f(q0, v), p0, 1e-6)
    assert np.abs(jq - nq).max() <= 1e-8
    assert np.abs(jp - np_).max() <= 1e-8
    assert np.abs(jp).max() > 0.1  # the parameters do move markers

"""Symbolic model parameters: file values reproduce the model, other values reproduce the
model written with those values, bad requests are refused."""

from __future__ import annotations

from pathlib import Path

import casadi as cs
import numpy as np
import pytest
from model_testing import random_poses

from nmsm.errors import ModelError
from nmsm.model import CasadiModel, ModelParameters, load_model
from nmsm.model.osim_writer import OsimWriter


def _parameters(model):
    params = ModelParameters(model)
    params.joint_frame_orientation("knee_r", "parent", components=(0, 2))
    params.joint_frame_translation("knee_r", "child")
    params.joint_frame_orientation("subtalar_r", "parent")
    params.marker_location("R_Heel" if "R_Heel" in model.marker_names else model.marker_names[0])
    params.body_scale("pelvis")
    params.body_scale("tibia_r")
    return params


def test_file_values_reproduce_the_model(shared_data: Path) -> None:
    model = load_model(shared_data / "models" / "RCNL2024.osim")
    params = _parameters(model)
    plain = CasadiModel(model)
    cm = CasadiModel(model, params)
    q = random_poses(model, plain, 3, np.random.default_rng(41))
    for row in q:
        assert np.abs(np.array(cm.marker_positions(row, params.initial_values))
                      - np.array(plain.marker_positions(row))).max() <= 1e-15
        tau_p = cm.inverse_dynamics_function()(row, row, row, params.initial_values)
        assert np.abs(np.array(tau_p) - np.array(plain.inverse_dynamics_function()(row, row, row))).max() <= 1e-11
    assert params.names[:2] == ["/jointset/knee_r/femur_r_offset/orientation/x", "/jointset/knee_r/femur_r_offset/orientation/z"]


def test_parameter_values_equal_the_written_model(shared_data: Path, tmp_path: Path, bridge) -> None:
    source = shared_data / "models" / "RCNL2024.osim"
    model = load_model(source)
    params = _parameters(model)
    values = params.initial_values + np.random.default_rng(42).normal(0, 0.05, params.size)
    writer = OsimWriter(source)
    writer.apply_parameters(params, values)
    written = writer.write(tmp_path / "personalized.osim")
    cm = CasadiModel(model, params)
    new_model = load_model(written)
    new = CasadiModel(new_model)
    q = random_poses(model, new, 3, np.random.default_rng(43))
    markers_p = np.stack([np.array(cm.marker_positions(row, values)) for row in q])
    markers_w = np.stack([np.array(new.marker_positions(row)) for row in q])
    assert np.abs(markers_p - markers_w).max() <= 1e-12
    for row in q:
        assert np.abs(np.array(cm.inverse_dynamics_function()(row, row, row, values))
                      - np.array(new.inverse_dynamics_function()(row, row, row))).max() <= 1e-9
    # and OpenSim reads the written model the same way
    ref = bridge.call("oracle_kinematics", path=str(written), q=q)
    order = [new_model.marker_names.index(n) for n in ref["marker_names"]]
    assert np.abs(markers_w.transpose(0, 2, 1)[:, order] - ref["markers"]).max() <= 1e-9


def test_mx_arguments_need_mx_parameters(shared_data: Path) -> None:
    model = load_model(shared_data / "jmp" / "toy_simple_arm" / "simple_arm.osim")
    params = ModelParameters(model)
    params.joint_frame_translation(model.joints[-1].name, "parent")
    cm = CasadiModel(model, params)
    q = cs.MX.sym("q", cm.n)
    with pytest.raises(ValueError, match="pass p="):
        cm.marker_positions(q)
    p = cs.MX.sym("p", params.size)
    f = cs.Function("f", [q, p], [cm.marker_positions(q, p)])
    assert f.size_out(0) == (3, len(model.markers))


def test_bad_parameter_requests(shared_data: Path) -> None:
    model = load_model(shared_data / "gcp" / "patient3_right_foot" / "footModel_1.osim")
    params = ModelParameters(model)
    with pytest.raises(ModelError, match="not a PhysicalOffsetFrame"):
        params.joint_frame_translation("ground_hindfoot", "child")  # the child frame is the body itself
    with pytest.raises(ModelError, match="no joint 'nothing'"):
        params.joint_frame_orientation("nothing", "parent")
    with pytest.raises(ModelError, match="no body"):
        params.body_scale("femur")
    params.body_scale("calcn_r")
    with pytest.raises(ValueError, match="already"):
        params.body_scale("calcn_r")
    with pytest.raises(ValueError, match="components"):
        params.joint_frame_orientation("mtp_r", "parent", components=(0, 3))

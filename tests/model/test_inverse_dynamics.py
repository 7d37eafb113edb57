"""Inverse dynamics against OpenSim's InverseDynamicsSolver for every shared model, and the
dynamics built on it (mass matrix, forward dynamics, actuators, exact mode)."""

from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np
import pytest
from model_testing import MODEL_FILES, random_poses

TOLERANCE = 1e-6  # N m or N


def _motion(model, cm, relative: str, count: int = 4):
    rng = np.random.default_rng(zlib.crc32(relative.encode()) + 1)
    q = random_poses(model, cm, count, rng)
    return q, rng.normal(0, 1.0, q.shape), rng.normal(0, 5.0, q.shape), rng


@pytest.mark.parametrize("relative", MODEL_FILES)
def test_inverse_dynamics_matches_opensim(relative: str, shared_data: Path, bridge, model_cache) -> None:
    model, cm = model_cache(shared_data / relative)
    q, u, udot, rng = _motion(model, cm, relative)
    k = len(q)
    # as the ID tool: muscles disabled, every other force of the model on (contact, actuators at zero control)
    reference = bridge.call("oracle_inverse_dynamics", path=model.source_file, q=q, u=u, udot=udot)
    ours = np.array(cm.inverse_dynamics_function(include_contact=True).map(k)(q.T, u.T, udot.T)).T
    assert np.abs(ours - reference).max() <= TOLERANCE
    # external loads (forces at points and torques, in ground) on two bodies; only gravity otherwise
    bodies = list(model.bodies)[-2:]
    loads = [{"body": b, "force": rng.normal(0, 300, (k, 3)), "point": rng.normal(0, 1, (k, 3)),
              "torque": rng.normal(0, 20, (k, 3))} for b in bodies]
    reference = bridge.call("oracle_inverse_dynamics", path=model.source_file, q=q, u=u, udot=udot, loads=loads,
                            forces="none")
    values = np.concatenate([np.stack([np.concatenate([L["force"][i], L["point"][i], L["torque"][i]])
                                       for L in loads], axis=1) for i in range(k)], axis=1)
    ours = np.array(cm.inverse_dynamics_function(bodies).map(k)(q.T, u.T, udot.T, values)).T
    assert np.abs(ours - reference).max() <= TOLERANCE


def test_mass_matrix_and_forward_dynamics(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    q, u, udot, _ = _motion(model, cm, "mass", 1)
    q, u, udot = q[0], u[0], udot[0]
    mass = np.array(cm.mass_matrix_function()(q))
    assert np.allclose(mass, mass.T, atol=1e-12)
    assert np.linalg.eigvalsh(mass).min() > 0
    no_gravity = cm.inverse_dynamics_function(gravity=False)
    zero = np.zeros(cm.n)
    assert np.allclose(mass @ udot, np.array(no_gravity(q, zero, udot)).ravel() - np.array(no_gravity(q, zero, zero)).ravel(),
                       atol=1e-9)
    tau = np.array(cm.inverse_dynamics_function()(q, u, udot)).ravel()
    recovered = np.array(cm.forward_dynamics_function()(q, u, tau)).ravel()
    assert np.allclose(recovered, udot, atol=1e-8)


def test_applied_generalized_forces_are_subtracted(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    q, u, udot, rng = _motion(model, cm, "applied", 1)
    applied = rng.normal(size=cm.n)
    plain = np.array(cm.inverse_dynamics_function()(q[0], u[0], udot[0])).ravel()
    with_applied = np.array(cm.inverse_dynamics_function(applied_forces=True)(q[0], u[0], udot[0], applied)).ravel()
    assert np.allclose(with_applied, plain - applied, atol=1e-12)


def test_actuator_generalized_forces(shared_data: Path, model_cache) -> None:
    model, cm = model_cache(shared_data / "models" / "RCNL2024.osim")
    q = random_poses(model, cm, 1, np.random.default_rng(9))[0]
    controls = np.linspace(-1, 1, len(model.actuators))
    tau = np.array(cm.actuator_generalized_forces_function()(q, controls)).ravel()
    expected = np.zeros(cm.n)
    for act, c in zip(model.actuators, controls):
        expected[model.coordinate_index(act.coordinate)] += act.optimal_force * c
    assert np.allclose(tau, expected, atol=1e-12)


def test_point_and_torque_actuators_do_virtual_work(tmp_path: Path) -> None:
    """J^T F: generalized forces of a point force equal the power it delivers per unit speed."""
    from nmsm.model import CasadiModel, load_model

    text = """<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000"><Model name="arm">
  <Ground name="ground"/>
  <BodySet name="bodyset"><objects>
    <Body name="upper"><mass>2</mass><mass_center>0 -0.2 0</mass_center><inertia>0.02 0.01 0.02 0 0 0</inertia></Body>
    <Body name="lower"><mass>1</mass><mass_center>0 -0.15 0</mass_center><inertia>0.01 0.005 0.01 0 0 0</inertia></Body>
  </objects></BodySet>
  <JointSet name="jointset"><objects>
    <BallJoint name="shoulder"><socket_parent_frame>/ground</socket_parent_frame><socket_child_frame>/bodyset/upper</socket_child_frame>
      <coordinates><Coordinate name="s0"/><Coordinate name="s1"/><Coordinate name="s2"/></coordinates></BallJoint>
    <UniversalJoint name="elbow"><socket_parent_frame>upper_offset</socket_parent_frame><socket_child_frame>/bodyset/lower</socket_child_frame>
      <coordinates><Coordinate name="e0"/><Coordinate name="e1"/></coordinates>
      <frames><PhysicalOffsetFrame name="upper_offset"><socket_parent>/bodyset/upper</socket_parent>
        <translation>0 -0.4 0</translation><orientation>0.1 0.2 0.3</orientation></PhysicalOffsetFrame></frames></UniversalJoint>
  </objects></JointSet>
  <ForceSet name="forceset"><objects>
    <PointActuator name="push"><body>lower</body><point>0.01 -0.3 0.02</point><point_is_global>false</point_is_global>
      <direction>1 2 0</direction><force_is_global>true</force_is_global><optimal_force>50</optimal_force></PointActuator>
    <TorqueActuator name="twist"><bodyA>lower</bodyA><bodyB>upper</bodyB><axis>0 0 1</axis>
      <torque_is_global>false</torque_is_global><optimal_force>7</optimal_force></TorqueActuator>
  </objects></ForceSet>
</Model></OpenSimDocument>"""
    path = tmp_path / "arm.osim"
    path.write_text(text)
    model = load_model(path)
    cm = CasadiModel(model)
    rng = np.random.default_rng(11)
    q = rng.uniform(-0.5, 0.5, cm.n)
    tau = np.array(cm.actuator_generalized_forces_function()(q, [0.8, -0.6])).ravel()
    # virtual power of the actuators for each unit speed
    direction = np.array([1.0, 2.0, 0.0]) / np.sqrt(5.0)
    force = 50 * 0.8 * direction
    velocity = cm.point_velocity_function("lower")
    r_lower = np.array(cm.body_pose("lower", q)[0])
    torque = -0.6 * 7 * r_lower @ np.array([0.0, 0.0, 1.0])
    for j in range(cm.n):
        e = np.zeros(cm.n)
        e[j] = 1.0
        v = np.array(velocity(q, e, [0.01, -0.3, 0.02])).ravel()
        w_lower = _angular_velocity(cm, "lower", q, e)
        w_upper = _angular_velocity(cm, "upper", q, e)
        assert tau[j] == pytest.approx(force @ v + torque @ (w_lower - w_upper), abs=1e-12)


def _angular_velocity(cm, body: str, q: np.ndarray, u: np.ndarray) -> np.ndarray:
    import casadi as cs

    state = cm.kinematics.forward(cm.q, cm.qdot)[body]
    return np.array(cs.Function("w", [cm.q, cm.qdot], [state.w])(q, u)).ravel()


def test_exact_mode_conserves_energy(shared_data: Path) -> None:
    """With exact velocity-product terms, tau . qdot = dT/dt + dV/dt along any path; the
    default (OpenSim's approximation for the RCNL knee) does not satisfy it exactly."""
    import casadi as cs

    from nmsm.model import CasadiModel, load_model

    model = load_model(shared_data / "models" / "RCNL2024.osim")
    exact = CasadiModel(model, custom_joint_bias="exact")
    opensim = CasadiModel(model)
    rng = np.random.default_rng(13)
    q0 = random_poses(model, exact, 1, rng)[0]
    v0 = rng.normal(size=exact.n)
    a0 = rng.normal(size=exact.n)
    mass = exact.mass_matrix_function()
    com = []
    for name, body in model.bodies.items():
        com.append((body.mass, exact.point_function(name)))
    g = np.array(model.gravity)

    def energy(t: float) -> float:
        q = q0 + v0 * t + 0.5 * a0 * t * t
        v = v0 + a0 * t
        kinetic = 0.5 * v @ np.array(mass(q)) @ v
        potential = -sum(m * g @ np.array(f(q, cs.DM(b.mass_center))).ravel()
                         for (m, f), b in zip(com, model.bodies.values()))
        return kinetic + potential

    h = 1e-5
    rate = (energy(h) - energy(-h)) / (2 * h)
    power_exact = np.array(exact.inverse_dynamics_function()(q0, v0, a0)).ravel() @ v0
    power_opensim = np.array(opensim.inverse_dynamics_function()(q0, v0, a0)).ravel() @ v0
    assert power_exact == pytest.approx(rate, rel=1e-7, abs=1e-6)
    assert abs(power_opensim - rate) > 1e-4  # OpenSim's CustomJoint approximation is visible here

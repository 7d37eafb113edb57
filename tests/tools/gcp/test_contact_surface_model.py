"""The contact model as Treatment Optimization uses it: ContactSurfaceModel on a full
CasadiModel (springs from an .osimx surface) agrees with GCP's per-frame computation, and
its per-body loads reproduce the springs' total force and moment."""

from __future__ import annotations

import casadi as cs
import numpy as np

from nmsm.io.osimx import GcpSpring, OsimxContactSurface
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.foot_contact import ContactSurfaceModel
from nmsm.model.osim import load_model
from nmsm.tools.gcp.run import load_feet


def test_matches_gcp_and_loads_are_consistent(synthetic_case):
    foot = _foot(synthetic_case)
    k = synthetic_case.spring_constants
    truth = synthetic_case.truth
    surface = _surface(synthetic_case)
    model = load_model(synthetic_case.model_file)
    contact = ContactSurfaceModel.from_osimx(surface, model)
    assert contact.bodies == ("calcn_r", "toes_r") and contact.n_springs == k.size
    cm = CasadiModel(model)
    order = [cm.coordinate_index(n) for n in ("mtp_angle_r", "foot_rotation_y_r", "foot_rotation_x_r",
                                               "foot_rotation_z_r", "foot_tx_r", "foot_ty_r", "foot_tz_r")]
    reactions = contact.ground_reactions_function(cm)
    loads = contact.body_loads_function(cm)
    kinematics = contact.spring_kinematics_function(cm)
    parameters = np.array([truth.damping_factor, truth.dynamic_friction_coefficient,
                           truth.viscous_friction_coefficient, truth.resting_spring_length,
                           truth.latching_velocity, truth.belt_speed])
    rng = np.random.default_rng(0)
    for t in (5, 30, 55):
        q_foot = foot.coordinates[t]
        qd_foot = rng.normal(0.0, 0.5, 7)
        q = np.zeros(cm.n)
        qd = np.zeros(cm.n)
        q[order], qd[order] = q_foot, qd_foot
        force, moment, per_spring = (np.array(v) for v in reactions(q, qd))
        _, _, a, b, _ = foot.frame_function(q_foot, qd_foot, parameters)
        expected = np.array(cs.mtimes(a, k) + b).ravel()
        np.testing.assert_allclose(np.concatenate([force.ravel(), moment.ravel()]), expected, rtol=1e-9, atol=1e-8)
        body_loads = np.array(loads(q, qd))
        np.testing.assert_allclose(body_loads[0:3].sum(axis=1), force.ravel(), rtol=1e-12, atol=1e-9)
        positions = np.array(kinematics(q, qd)[0])
        point = np.array([0.1, 0.0, 0.2])
        true_moment = np.cross((positions.T - point), per_spring.T).sum(axis=0)
        from_loads = sum(body_loads[6:9, i] + np.cross(body_loads[3:6, i] - point, body_loads[0:3, i]) for i in range(2))
        np.testing.assert_allclose(from_loads, true_moment, rtol=1e-10, atol=1e-8)


def _foot(synthetic_case):
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(synthetic_case.settings_file))
    return load_feet(settings)[0][0]


def _surface(synthetic_case, copies: int = 1) -> OsimxContactSurface:
    """The synthetic case's right-foot surface, its springs repeated ``copies`` times."""
    foot = _foot(synthetic_case)
    truth = synthetic_case.truth
    springs = tuple(GcpSpring(f"{n}_{c}", b, tuple(loc), float(kk)) for c in range(copies) for n, b, loc, kk in
                    zip(foot.springs.names, foot.springs.bodies, foot.springs.locations, synthetic_case.spring_constants))
    return OsimxContactSurface(
        is_left_foot=False, belt_speed=truth.belt_speed, force_columns=("a", "b", "c"), moment_columns=("d", "e", "f"),
        electrical_center_columns=("g", "h", "i"), hindfoot_body="calcn_r", toe_marker="R_Toe",
        medial_marker="R_Toe_Medial", lateral_marker="R_Toe_Lateral", heel_marker="R_Heel",
        midfoot_superior_marker="R_Midfoot_Superior", resting_spring_length=truth.resting_spring_length,
        dynamic_friction_coefficient=truth.dynamic_friction_coefficient,
        viscous_friction_coefficient=truth.viscous_friction_coefficient, damping_factor=truth.damping_factor,
        latching_velocity=truth.latching_velocity, springs=springs)


def test_spring_kinematics_equal_each_point_on_its_body(synthetic_case) -> None:
    model = load_model(synthetic_case.model_file)
    contact = ContactSurfaceModel.from_osimx(_surface(synthetic_case), model)
    cm = CasadiModel(model)
    rng = np.random.default_rng(1)
    q, qd = rng.normal(0.0, 0.3, cm.n), rng.normal(0.0, 1.0, cm.n)
    positions, velocities = (np.array(v) for v in contact.spring_kinematics_function(cm)(q, qd))
    for j, (body, location) in enumerate(zip(contact.spring_bodies, contact.spring_locations)):
        np.testing.assert_allclose(np.array(cm.point_function(body)(q, location)).ravel(), positions[:, j],
                                   rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(np.array(cm.point_velocity_function(body)(q, qd, location)).ravel(),
                                   velocities[:, j], rtol=1e-12, atol=1e-14)


def test_a_spring_adds_a_few_operations_not_a_kinematic_chain(synthetic_case, tutorial) -> None:
    """Each foot body's pose and motion are computed once for all its springs: on the GCP
    tutorial's full-body model a spring's position and velocity cost a few dozen SX
    operations (rotation of its location, cross product with the angular velocity), where
    the kinematic chain from the ground to the toes costs hundreds."""
    model = load_model(tutorial / "bodyModel.osim")
    cm = CasadiModel(model)
    one = ContactSurfaceModel.from_osimx(_surface(synthetic_case, 1), model)
    two = ContactSurfaceModel.from_osimx(_surface(synthetic_case, 2), model)
    q, qd = cs.SX.sym("q", cm.n), cs.SX.sym("qd", cm.n)  # new symbols, as a contact model's point function has

    def size(contact: ContactSurfaceModel) -> int:
        return cs.Function("springs", [q, qd], list(contact.spring_kinematics(cm, q, qd))).n_instructions()

    per_spring = (size(two) - size(one)) / one.n_springs
    chain = cm.point_function("toes_r").n_instructions()
    assert per_spring < 60 and chain > 500, (per_spring, chain)

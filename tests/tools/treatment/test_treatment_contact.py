"""Contact models in Treatment Optimization (GCP's elastic foundation on the tutorial subject)."""

from __future__ import annotations

import warnings
from pathlib import Path

import casadi as cs
import numpy as np
import pytest

from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage
from nmsm.tools.treatment.model_adapter import OsimTreatmentModel

GCP = ("gcp", "uf_subject3_tutorial")


def _gcp(shared: Path) -> Path:
    return shared.joinpath(*GCP)


def test_contact_loads_enter_inverse_dynamics_by_virtual_work(shared_data: Path) -> None:
    folder = _gcp(shared_data)
    model = OsimTreatmentModel(folder / "bodyModel.osim")
    surface = read_osimx(folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").contact_surfaces[0]
    contact = ElasticFoundationContact(surface, model.model, 0)
    ik = read_storage(folder / "preprocessed" / "IKData" / "gait_1.sto")
    rotational = {c for c in model.coordinate_names if model.is_rotational(c)}
    ik = ik.to_radians(rotational)
    q = ik.columns(model.coordinate_names)[40]  # mid stance of the right foot
    rng = np.random.default_rng(1)
    qd, qdd = rng.normal(0, 0.5, q.size), rng.normal(0, 2.0, q.size)
    f = contact.point_function(model)
    p = np.asarray(contact.surface.parameters.vector())
    loads, force, moment, point = (np.asarray(v) for v in f(q, qd, p))
    assert force[1] > 50  # the foot is loaded
    tau = np.asarray(model.inverse_dynamics_function(contact.load_bodies)(q, qd, qdd, loads)).ravel()
    tau0 = np.asarray(model.inverse_dynamics_function()(q, qd, qdd)).ravel()
    # generalized force of the springs: sum_j J_j^T F_j (F_j: spring force on its body)
    qs = cs.SX.sym("q", q.size)
    cm = model.casadi
    from nmsm.model.foot_contact import spring_forces

    positions, velocities = [], []
    for body, loc in zip(contact.surface.spring_bodies, contact.surface.spring_locations):
        positions.append(cm.point_function(body)(q, cs.DM(loc)))
        velocities.append(cm.point_velocity_function(body)(q, qd, cs.DM(loc)))
    forces = np.asarray(spring_forces(cs.horzcat(*positions), cs.horzcat(*velocities),
                                      cs.DM(contact.surface.spring_constants), cs.DM(p)))
    generalized = np.zeros(q.size)
    for j, (body, loc) in enumerate(zip(contact.surface.spring_bodies, contact.surface.spring_locations)):
        jac = cs.Function("J", [qs], [cs.jacobian(cm.point_function(body)(qs, cs.DM(loc)), qs)])
        generalized += np.asarray(jac(q)).T @ forces[:, j]
    assert np.allclose(tau, tau0 - generalized, atol=1e-6 * np.max(np.abs(tau0)))
    assert np.allclose(force.ravel(), forces.sum(axis=1), rtol=1e-10)


SETTINGS = """<NMSMPipelineDocument Version="1.5.0"><TrackingOptimizationTool>
 <results_directory>{out}</results_directory>
 <initial_guess_directory>{data}/preprocessed</initial_guess_directory>
 <tracked_quantities_directory>{data}/preprocessed</tracked_quantities_directory>
 <input_model_file>{data}/bodyModel.osim</input_model_file>
 <input_osimx_file>{data}/CompletedSettingsFiles/GCPResultsV4/bodyModel_gcp.osimx</input_osimx_file>
 <optimal_control_solver_settings_file>{solver}</optimal_control_solver_settings_file>
 <trial_name>gait_1</trial_name><states_coordinate_list>{states}</states_coordinate_list>
 <RCNLTorqueController><coordinate_list>{states}</coordinate_list></RCNLTorqueController>
 <RCNLCostTermSet>
  <RCNLCostTerm><is_enabled>true</is_enabled><type>generalized_coordinate_tracking</type>
   <coordinate_list>{states}</coordinate_list><max_allowable_error>0.05</max_allowable_error></RCNLCostTerm>
  <RCNLCostTerm><is_enabled>true</is_enabled><type>external_force_tracking</type>
   <force_list>ground_force_2_vx ground_force_2_vy</force_list><max_allowable_error>50</max_allowable_error></RCNLCostTerm>
 </RCNLCostTermSet>
 <RCNLConstraintTermSet><RCNLConstraintTerm><is_enabled>true</is_enabled><type>kinetic_consistency</type>
  <load_list>{loads}</load_list><max_error>1</max_error><min_error>-1</min_error></RCNLConstraintTerm>
 </RCNLConstraintTermSet></TrackingOptimizationTool></NMSMPipelineDocument>"""
SOLVER = """<NMSMPipelineDocument Version="1.5.0"><OptimalControlSolverSettings><GpopsSettings>
 <setup_mesh_method>none</setup_mesh_method><setup_mesh_phase_intervals>6</setup_mesh_phase_intervals>
 <setup_mesh_phase_colpoints_per_Interval>3</setup_mesh_phase_colpoints_per_Interval>
 <setup_nlp_linear_solver>mumps</setup_nlp_linear_solver><setup_nlp_tolerance>1e-3</setup_nlp_tolerance>
 <setup_nlp_max_iterations>200</setup_nlp_max_iterations><setup_display_level>0</setup_display_level>
</GpopsSettings></OptimalControlSolverSettings></NMSMPipelineDocument>"""


@pytest.mark.slow
def test_tracking_with_ground_contact(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.tools.treatment.run import run_settings

    states = "hip_flexion_r knee_angle_r ankle_angle_r"
    loads = " ".join(f"{c}_moment" for c in states.split())
    (tmp_path / "solver.xml").write_text(SOLVER)
    path = tmp_path / "to.xml"
    path.write_text(SETTINGS.format(out=tmp_path / "out", data=_gcp(shared_data), solver=tmp_path / "solver.xml",
                                    states=states, loads=loads))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = run_settings(path)
    assert run.solution.success, run.summary
    assert run.cost < run.initial_cost
    grf = read_storage(tmp_path / "out" / "GRFData" / "gait_1.sto")
    assert grf.has("ground_force_2_vy") and np.max(grf.column("ground_force_2_vy")) > 100

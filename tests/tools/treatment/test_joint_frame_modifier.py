"""Joint-frame model functions (DO): a joint's frame as a design parameter.

Known answer: the toy arm's elbow moments are generated with its parent frame turned by
TRUE_ANGLE about the elbow axis; a Design Optimization of the file's arm (angle 0) that tracks
the elbow angle and those moments recovers the angle. The context's inverse dynamics, markers
and orientations follow the parameter exactly (compared with the parametric model core).
"""

from __future__ import annotations

from types import SimpleNamespace

import casadi as cs
import numpy as np
import pytest

from nmsm.controllers.torque import TorqueController
from nmsm.errors import InputError
from nmsm.model import CasadiModel, load_model
from nmsm.model.parameters import ModelParameters
from nmsm.modifiers.joint_frame import ApplyJointFrameOrientationParameter
from nmsm.terms.treatment.inverse_dynamics import InverseDynamicsLoadTracking
from nmsm.terms.treatment.kinematics import GeneralizedCoordinateTracking
from nmsm.core.bounds import RangeRule, range_bounds
from nmsm.core.controller_setup import ControllerSetup
from nmsm.tools.treatment.formulation import StateSetup, build_problem
from nmsm.tools.treatment.model_adapter import OsimTreatmentModel
from nmsm.tools.treatment.modifiers import ModificationTarget
from nmsm.tools.treatment.problem_data import TreatmentData
from nmsm.core.splines import ReferenceSplines
from nmsm.core.transcription.mesh import Mesh

DURATION = 1.0
TRUE_ANGLE = 0.12  # rad, elbow parent frame about its z axis (the flexion axis)
PARAMETER = "joint_frame_orientation_elbow"
COORDINATE = "r_elbow_flex"


@pytest.fixture(scope="module")
def arm(shared_data):
    return load_model(shared_data / "jmp" / "toy_simple_arm" / "simple_arm.osim")


def _file_angle(model) -> float:
    """The file's elbow parent-frame z orientation (rad): parameter values are absolute."""
    params = ModelParameters(model)
    params.joint_frame_orientation("r_elbow", "parent", components=(2,))
    return float(params.initial_values[0])


def _references(model) -> tuple[ReferenceSplines, ReferenceSplines]:
    """Elbow motion and its inverse dynamics with the frame turned by TRUE_ANGLE."""
    t = np.linspace(0.0, DURATION, 61)
    q = 1.0 + 0.5 * np.sin(2 * np.pi * t)
    qd = 0.5 * 2 * np.pi * np.cos(2 * np.pi * t)
    qdd = -0.5 * (2 * np.pi) ** 2 * np.sin(2 * np.pi * t)
    params = ModelParameters(model)
    params.joint_frame_orientation("r_elbow", "parent", components=(2,))
    truth = np.array(params.initial_values)
    truth[0] += TRUE_ANGLE
    inverse = CasadiModel(model, params).inverse_dynamics_function()
    tau = np.array([float(inverse(q[k], qd[k], qdd[k], truth)) for k in range(t.size)])
    coords = ReferenceSplines(t, (COORDINATE,), q[:, None])
    loads = ReferenceSplines(t, (f"{COORDINATE}_moment",), tau[:, None])
    return coords, loads


def _settings(axes: str = "z", joint: str = "r_elbow") -> SimpleNamespace:
    term = SimpleNamespace(type=PARAMETER, fields={"joint": joint, "frame": "parent", "axes": axes})
    return SimpleNamespace(parameter_terms=[term], settings_file="design.xml")


def _build(model, terms, *, start: float = 0.0, settings: SimpleNamespace | None = None):
    adapter = OsimTreatmentModel(model)
    coords, loads = _references(model)
    refs = {"coordinates": coords, "loads": loads}
    mesh = Mesh.uniform(5, 5)
    s_col = mesh.times("collocation")
    setup = ControllerSetup("DO", adapter, s_col * DURATION, DURATION, refs, {"loads": loads})
    data = TreatmentData("DO", adapter, (COORDINATE,), refs, coords, DURATION, DURATION, (DURATION, DURATION))
    data.controllers = [TorqueController.from_settings({"coordinate_list": COORDINATE}, setup)]
    t = coords.time
    lo_q, hi_q = range_bounds(coords.values(t, 0, (COORDINATE,)), RangeRule(2))
    lo_v, hi_v = range_bounds(coords.values(t, 1, (COORDINATE,)), RangeRule(1.5))
    lo_a, hi_a = range_bounds(coords.values(t, 2, (COORDINATE,)), RangeRule(1))
    tn = mesh.times("nodes") * DURATION
    guess = np.hstack([coords.values(tn, 0, (COORDINATE,)), coords.values(tn, 1, (COORDINATE,))])
    states = StateSetup(np.r_[lo_q, lo_v], np.r_[hi_q, hi_v], lo_a, hi_a, guess,
                        coords.values(s_col * DURATION, 2, (COORDINATE,)))
    chosen = settings or _settings()

    def declare(problem, data):
        data.parameters[PARAMETER] = problem.variable("parameter:" + PARAMETER, np.array([start]),
                                                      np.array([start - 0.3]), np.array([start + 0.3]))
        modifier = ApplyJointFrameOrientationParameter("applyJointFrameOrientationParameter", "design.xml")
        modifier.apply(ModificationTarget(data, chosen), data.parameters)

    return build_problem(data, mesh, states, list(terms), declare_extra=declare)


def _at_guess(built, expression):
    problem = built.problem
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    return np.asarray(problem.evaluate(cs.MX(expression), x0))


def test_context_follows_the_parameter(arm) -> None:
    """ID, a marker, the centre of mass and the forearm's orientation at the guess (parameter
    0.2 rad) follow the parametric model core at the same value; the tracked marker stays the
    file's."""
    built = _build(arm, [GeneralizedCoordinateTracking(coordinate=COORDINATE)], start=_file_angle(arm) + 0.2)
    assert built.context._q.data.model.parameter_count == 1
    view = built.context.at("nodes")
    q = _at_guess(built, view.positions())
    qd = _at_guess(built, view.speeds())
    qdd = _at_guess(built, view.accelerations())
    core = built.context._q.data.model.casadi
    p = np.array([_file_angle(arm) + 0.2])
    tau = _at_guess(built, view.inverse_dynamics())
    expected = np.array([np.asarray(core.inverse_dynamics_function()(q[k], qd[k], qdd[k], p)).ravel()
                         for k in range(q.shape[0])])
    np.testing.assert_allclose(tau, expected, atol=1e-10)
    marker = arm.marker_names[-1]
    position = _at_guess(built, view.marker_position(marker))
    expected = np.array([np.asarray(core.marker_function([marker])(q[k], p)).ravel() for k in range(q.shape[0])])
    np.testing.assert_allclose(position, expected, atol=1e-12)
    file_model = CasadiModel(arm)
    tracked = np.asarray(built.context._q.tracked_marker("nodes", marker)[0])
    q_tracked = built.context._q.data.tracked_full_kinematics(built.context._q.reference_times("nodes"))[0]
    expected = np.array([np.asarray(file_model.marker_function([marker])(q_tracked[k])).ravel()
                         for k in range(q_tracked.shape[0])])
    np.testing.assert_allclose(tracked, expected, atol=1e-12)
    com = _at_guess(built, view.center_of_mass_position())
    expected = np.array([np.asarray(core.center_of_mass_function()(q[k], p)).ravel() for k in range(q.shape[0])])
    np.testing.assert_allclose(com, expected, atol=1e-12)
    from nmsm.tools.treatment.orientation import euler_angles

    turned = _at_guess(built, view.body_orientation("r_ulna_radius_hand", "xyz"))
    pose = core.body_pose_function("r_ulna_radius_hand")
    expected = np.array([[float(x) for x in euler_angles(pose(q[k], p)[0], "xyz")] for k in range(q.shape[0])])
    np.testing.assert_allclose(turned, expected, atol=1e-12)
    plain = OsimTreatmentModel(arm).body_rotation_function("r_ulna_radius_hand")
    unturned = np.array([[float(x) for x in euler_angles(plain(q[k]), "xyz")] for k in range(q.shape[0])])
    assert np.abs(turned - unturned).max() > 0.1  # the frame did turn


def test_design_optimization_recovers_the_frame(arm) -> None:
    terms = [GeneralizedCoordinateTracking(coordinate=COORDINATE, max_allowable_error=0.01),
             InverseDynamicsLoadTracking(load=f"{COORDINATE}_moment", max_allowable_error=0.01)]
    built = _build(arm, terms, start=_file_angle(arm))
    solution = built.problem.solve("ipopt", print_level=0, tol=1e-10)
    assert solution.success, solution.status
    recovered = float(np.asarray(solution.values["parameter:" + PARAMETER]).ravel()[0])
    truth = _file_angle(arm) + TRUE_ANGLE
    print(f"recovered {recovered:.8f} rad (truth {truth}), {solution.iterations} iterations")
    assert abs(recovered - truth) < 1e-4, recovered


def test_bad_joint_frame_settings(arm) -> None:
    with pytest.raises(InputError, match="no_such_joint"):
        _build(arm, [GeneralizedCoordinateTracking(coordinate=COORDINATE)], settings=_settings(joint="no_such_joint"))
    with pytest.raises(InputError, match="<axes>"):
        _build(arm, [GeneralizedCoordinateTracking(coordinate=COORDINATE)], settings=_settings(axes="z w"))
    with pytest.raises(InputError, match="1 values for 2 axes"):
        _build(arm, [GeneralizedCoordinateTracking(coordinate=COORDINATE)], settings=_settings(axes="x z"))


def test_settings_file_run_writes_the_designed_model(shared_data, tmp_path) -> None:
    """The kicking tutorial's torque DO V1 (fastest toe) with the knee's parent frame free to
    turn about z, from a settings file: the solution's angle is written to
    ``<trial>_parameterSolution.xml`` and into ``KickingModelDesignOpt.osim``, whose only change
    is that element."""
    import re

    from nmsm.tools.treatment.run import run_settings

    root = shared_data / "treatment" / "torque_kick_tutorial"
    folder = root / "CompletedSettingsFiles"
    text = (folder / "TorqueDOSettingsV1.xml").read_text()
    for tag in ("initial_guess_directory", "tracked_quantities_directory"):
        text = re.sub(f"<{tag}>([^<]*)</{tag}>", lambda m, tag=tag: f"<{tag}>{folder / m.group(1)}</{tag}>", text)
    text = re.sub(r"<input_model_file>[^<]*</input_model_file>",
                  f"<input_model_file>{root / 'KickingModel.osim'}</input_model_file>", text)
    text = re.sub(r"<optimal_control_solver_settings_file>[^<]*</optimal_control_solver_settings_file>",
                  f"<optimal_control_solver_settings_file>{root / 'GpopsSettings.xml'}"
                  "</optimal_control_solver_settings_file>", text)
    start = 0.124616326794065  # the file's value
    text = text.replace("<RCNLTorqueController>", f"""<model_functions>applyJointFrameOrientationParameter</model_functions>
        <RCNLParameterTermSet><RCNLParameterTerm><type>joint_frame_orientation_knee</type>
        <joint>knee_r</joint><frame>parent</frame><axes>z</axes><initial_values>{start}</initial_values>
        <lower_bounds>{start - 0.1}</lower_bounds><upper_bounds>{start + 0.1}</upper_bounds>
        </RCNLParameterTerm></RCNLParameterTermSet>
        <RCNLTorqueController>""", 1)
    settings = tmp_path / "DesignKnee.xml"
    settings.write_text(text)
    run = run_settings(settings, results_directory=tmp_path / "results", print_level=0)
    assert run.solution.success, run.solution.status
    angle = float(np.asarray(run.solution.values["parameter:joint_frame_orientation_knee"]).ravel()[0])
    solution_file = (tmp_path / "results" / "drive_kick1_parameterSolution.xml").read_text()
    assert repr(angle) in solution_file
    written = load_model(tmp_path / "results" / "KickingModelDesignOpt.osim")
    frame = written.frames[ModelParameters(written).joint_frame_path("knee_r", "parent")]
    assert frame.orientation[2] == pytest.approx(angle, abs=1e-12)
    before = (root / "KickingModel.osim").read_text().splitlines()
    after = (tmp_path / "results" / "KickingModelDesignOpt.osim").read_text().splitlines()
    changed = [k for k, (a, b) in enumerate(zip(before, after)) if a != b]
    assert len(before) == len(after) and len(changed) == 1 and "<orientation>" in after[changed[0]]


def test_elastic_foundation_contact_follows_the_frame(shared_data) -> None:
    """GCP's spring contact on the tutorial body model with the ankle's parent frame as a
    parameter: at the file's value the contact equals the file model's; moved 1 cm, the
    springs move with the foot (forces change) and the reference point is the moved marker's."""
    from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
    from nmsm.io.osimx import read_osimx
    from nmsm.io.storage import read_storage

    folder = shared_data / "gcp" / "uf_subject3_tutorial"
    body = load_model(folder / "bodyModel.osim")
    surface = read_osimx(folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").contact_surfaces[0]
    plain_model = OsimTreatmentModel(body)
    params = ModelParameters(body)
    params.joint_frame_translation("ankle_r", "parent", components=(1,))
    moved_model = OsimTreatmentModel(body, params)
    contact = ElasticFoundationContact(surface, body, 0)
    ik = read_storage(folder / "preprocessed" / "IKData" / "gait_1.sto")
    ik = ik.to_radians({c for c in plain_model.coordinate_names if plain_model.is_rotational(c)})
    q = ik.columns(plain_model.coordinate_names)[40]
    qd = np.random.default_rng(2).normal(0, 0.5, q.size)
    p_contact = np.asarray(contact.surface.parameters.vector(), dtype=float)
    plain = [np.asarray(v) for v in contact.point_function(plain_model)(q, qd, p_contact)]
    moved_function = contact.point_function(moved_model)
    assert moved_function.size1_in(2) == p_contact.size + 1
    at_file = [np.asarray(v) for v in moved_function(q, qd, np.r_[p_contact, params.initial_values])]
    for a, b in zip(plain, at_file):
        np.testing.assert_allclose(b, a, atol=1e-12)
    shifted = params.initial_values + 0.01
    moved = [np.asarray(v) for v in moved_function(q, qd, np.r_[p_contact, shifted])]
    assert np.abs(moved[1] - plain[1]).max() > 1.0  # N: the springs moved with the foot
    marker = np.asarray(moved_model.casadi.marker_function([surface.midfoot_superior_marker])(q, shifted)).ravel()
    np.testing.assert_allclose(moved[3].ravel()[[0, 2]], marker[[0, 2]], atol=1e-12)
    # the target binds the contact to the parameters' values
    data = SimpleNamespace(model=plain_model, contact_models=[contact], controllers=[], model_parameter_values=None)
    ModificationTarget(data, SimpleNamespace(settings_file="design.xml")).set_joint_frame(
        "ankle_r", "parent", "translation", [1], [float(params.initial_values[0])])
    assert contact.parameters().shape == (1, p_contact.size + 1)


def test_design_with_ground_contact_starts_where_tracking_does(shared_data, tmp_path) -> None:
    """A DO of the GCP tutorial's body model with ground contact, kinetic consistency and the
    ankle's parent frame as a parameter at the file's value has the same starting cost as the
    same problem as a TO: the contact, inverse dynamics and tracked reactions (moments about
    the midfoot marker's floor point) follow the parameter consistently (``evaluate_only``)."""
    import warnings

    from test_treatment_contact import SETTINGS, SOLVER, _gcp

    from nmsm.tools.treatment.run import run_settings

    states = "hip_flexion_r knee_angle_r ankle_angle_r"
    loads = " ".join(f"{c}_moment" for c in states.split())
    (tmp_path / "solver.xml").write_text(SOLVER)
    tracking = SETTINGS.format(out=tmp_path / "to", data=_gcp(shared_data), solver=tmp_path / "solver.xml",
                               states=states, loads=loads).replace("</RCNLCostTermSet>", """<RCNLCostTerm>
        <is_enabled>true</is_enabled><type>external_moment_tracking</type>
        <moment_list>ground_moment_2_mx ground_moment_2_mz</moment_list><max_allowable_error>5</max_allowable_error>
        </RCNLCostTerm></RCNLCostTermSet>""")
    params = ModelParameters(load_model(_gcp(shared_data) / "bodyModel.osim"))
    params.joint_frame_translation("ankle_r", "parent", components=(1,))
    file_value = float(params.initial_values[0])
    design = tracking.replace("TrackingOptimizationTool>", "DesignOptimizationTool>").replace(
        f"<results_directory>{tmp_path / 'to'}</results_directory>",
        f"<results_directory>{tmp_path / 'do'}</results_directory>").replace(
        "<RCNLTorqueController>", f"""<model_functions>applyJointFrameTranslationParameter</model_functions>
        <RCNLParameterTermSet><RCNLParameterTerm><type>joint_frame_translation_ankle</type>
        <joint>ankle_r</joint><frame>parent</frame><axes>y</axes><initial_values>{file_value!r}</initial_values>
        <lower_bounds>{file_value - 0.02!r}</lower_bounds><upper_bounds>{file_value + 0.02!r}</upper_bounds>
        </RCNLParameterTerm></RCNLParameterTermSet><RCNLTorqueController>""", 1)
    (tmp_path / "to.xml").write_text(tracking)
    (tmp_path / "do.xml").write_text(design)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        to = run_settings(tmp_path / "to.xml", evaluate_only=True)
        do = run_settings(tmp_path / "do.xml", evaluate_only=True)
    assert do.prepared.data.model.parameter_count == 1 and to.prepared.data.model.parameter_count == 0
    assert do.initial_cost == pytest.approx(to.initial_cost, rel=1e-12)

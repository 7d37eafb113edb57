"""The Moco 2D gait problem: foot contact and muscle forces against OpenSim, the problem
builds and solves (coarse mesh); full 50-interval runs and the Moco comparison are slow."""

from __future__ import annotations

import warnings
from pathlib import Path

import attrs
import casadi as cs
import numpy as np
import pytest

from nmsm.controllers.contact.smooth_sphere import SmoothSphereContact
from nmsm.examples.moco2d import (COORDINATES, GRF_COLUMNS, MUSCLE_COORDINATES, read_solution, tracking_error,
                                  write_problem)

MODEL = ("moco2d", "2D_gait.osim")


def _solve(problem, **ipopt_options):
    """Run a written problem's settings with its objective scaling (warnings silenced)."""
    from nmsm.tools.treatment.run import run_settings

    options = {"ipopt_options": ipopt_options} if ipopt_options else {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_settings(problem.settings, results_directory=problem.results,
                            objective_scaling=problem.objective_factor, **options)


class _Setup:
    """What ``SmoothSphereContact.discover`` reads from a problem's controller setup."""

    def __init__(self, model, grf_labels=()):
        self.model = model
        labels = set(grf_labels)
        self.references = {"ground_reactions": _Has(labels)} if labels else {}


class _Has:
    def __init__(self, labels):
        self.labels = labels

    def has(self, label):
        return label in self.labels


def _states(names, count, rng):
    q = rng.uniform(-0.3, 0.3, (count, len(names)))
    q[:, names.index("pelvis_ty")] = rng.uniform(0.85, 0.95, count)  # feet around the floor
    q[:, names.index("pelvis_tx")] = rng.uniform(-1, 1, count)
    return q, rng.normal(0, 0.5, q.shape)


def test_foot_contact_models_match_opensim(shared_data: Path, bridge) -> None:
    from nmsm.tools.treatment.model_adapter import OsimTreatmentModel

    path = shared_data.joinpath(*MODEL)
    model = OsimTreatmentModel(path)
    names = list(model.coordinate_names)
    per_element = SmoothSphereContact.discover(_Setup(model))
    assert [c.name for c in per_element] == ["contactHeel_r", "contactHeel_l", "contactFront_r", "contactFront_l"]
    feet = SmoothSphereContact.discover(_Setup(model, GRF_COLUMNS))
    assert [c.name for c in feet] == ["ground_force_r", "ground_force_l"]
    assert feet[0].force_labels == ("ground_force_r_vx", "ground_force_r_vy", "ground_force_r_vz")
    assert feet[0].moment_labels == ("ground_torque_r_x", "ground_torque_r_y", "ground_torque_r_z")
    q, u = _states(names, 12, np.random.default_rng(5))
    ref = bridge.call("oracle_contact_forces", path=str(path), q=q, u=u)
    index = {n: i for i, n in enumerate(ref["names"])}
    loaded = 0
    for foot, side in zip(feet, "rl"):
        f = foot.point_function(model)
        for k in range(len(q)):
            _, force, moment, _ = (np.asarray(v).ravel() for v in f(q[k], u[k], np.zeros(0)))
            expected = ref["forces"][k, index[f"contactHeel_{side}"]] + ref["forces"][k, index[f"contactFront_{side}"]]
            assert np.allclose(force, expected, rtol=0, atol=1e-8 * max(1.0, np.abs(expected).max()))
            loaded += expected[1] > 50
    assert loaded >= 6  # real contact, not only smoothing tails
    # the feet's loads (force at the ground origin + moment) give the same inverse dynamics as the elements'
    rng = np.random.default_rng(6)
    qdd = rng.normal(0, 3, q.shape)
    reference = model.casadi.inverse_dynamics_function(include_contact=True)  # checked against OpenSim in tests/model
    for layout in (per_element, feet):
        bodies = tuple(b for c in layout for b in c.load_bodies)
        tau_f = model.inverse_dynamics_function(bodies)
        for k in range(3):
            loads = cs.horzcat(*[c.point_function(model)(q[k], u[k], np.zeros(0))[0] for c in layout])
            tau = np.asarray(tau_f(q[k], u[k], qdd[k], loads)).ravel()
            expected = np.asarray(reference(q[k], u[k], qdd[k])).ravel()
            assert np.allclose(tau, expected, atol=1e-8 * max(1.0, np.abs(expected).max()))


def test_foot_reaction_is_an_equivalent_load_about_its_ground_point(shared_data: Path) -> None:
    """Each foot's reported (force, point, torque): the point on the ground (y = 0) below the
    normal-force weighted mean of its contact points and the torque its moment about that
    point, so that F at the point plus the torque has the elements' moment about the ground
    origin (what an OpenSim ExternalForce applies)."""
    from nmsm.tools.treatment.model_adapter import OsimTreatmentModel

    model = OsimTreatmentModel(shared_data.joinpath(*MODEL))
    names = list(model.coordinate_names)
    feet = SmoothSphereContact.discover(_Setup(model, GRF_COLUMNS))
    elements = model.casadi.contact_force_function()
    q, u = _states(names, 8, np.random.default_rng(9))
    loaded = 0
    for foot in feet:
        f = foot.point_function(model)
        for k in range(len(q)):
            _, force, moment, point = (np.asarray(v).ravel() for v in f(q[k], u[k], np.zeros(0)))
            forces, points = (np.asarray(v) for v in elements(q[k], u[k]))
            about_origin = sum(np.cross(points[:, i], forces[:, i]) for i in foot.indices)
            assert point[1] == 0.0
            # the point: the contact points' mean weighted by each element's |normal force|
            normal = np.abs(forces[1, list(foot.indices)])
            mean = points[:, list(foot.indices)] @ normal / (normal.sum() + 1e-6)
            np.testing.assert_allclose(point[[0, 2]], mean[[0, 2]], rtol=0, atol=1e-12)
            np.testing.assert_allclose(moment + np.cross(point, force), about_origin, rtol=0,
                                       atol=1e-9 * max(1.0, np.abs(about_origin).max()))
            loaded += force[1] > 50
    assert loaded >= 4


def test_degroote_muscle_forces_match_opensim(shared_data: Path, bridge) -> None:
    from nmsm.controllers.muscle import DeGrooteMuscleModel, PathGeometry
    from nmsm.model import load_model
    from nmsm.model.muscle_model import MuscleModel

    path = shared_data.joinpath(*MODEL)
    model = load_model(path)
    names = [m.name for m in model.muscles]
    assert len(names) == 18
    base = MuscleModel.build(names, MUSCLE_COORDINATES, PathGeometry(model, MUSCLE_COORDINATES), model, None, 10.0)
    damping = np.array([float(model.muscle(m).properties["fiber_damping"]) for m in names])
    dgf = DeGrooteMuscleModel(base.muscles, base.coordinates, base.surrogate, base.parameters, base.pennation,
                              base.vmax_factor, damping=damping)
    f = dgf.point_function()
    rng = np.random.default_rng(3)
    q = rng.uniform(-0.4, 0.4, (6, 6))
    q[:, 2:4] = -np.abs(q[:, 2:4])  # knees flexed
    u = rng.normal(0, 2, q.shape)
    a = rng.uniform(0.01, 1, (6, len(names)))
    p = np.asarray(cs.evalf(base.parameter_row())).ravel()
    ours = [np.hstack([np.asarray(v).ravel() for v in f(q[k], u[k], a[k], p)]) for k in range(len(q))]
    ours = np.asarray(ours)
    M = len(names)
    ref = bridge.call("muscle_tendon_forces", model_file=str(path), coordinates=list(MUSCLE_COORDINATES), q=q, u=u,
                      activation=a)
    assert ref["names"] == names
    assert np.abs(ours[:, :M] - ref["tendon_force"]).max() <= 1e-8 * np.abs(ref["tendon_force"]).max()
    assert np.allclose(ours[:, M + 6:2 * M + 6], ref["normalized_fiber_length"], atol=1e-10)
    assert np.allclose(ours[:, 2 * M + 6:], ref["normalized_fiber_velocity"], atol=1e-10)
    # the rigid-tendon NMSM Hill model differs from DeGrooteFregly2016 (passive and force-velocity curves)
    nmsm = np.asarray([np.asarray(base.point_function()(q[k], u[k], a[k], p)[0]).ravel() for k in range(len(q))])
    assert np.abs(nmsm - ref["tendon_force"]).max() > 1.0


def test_activation_dynamics_matches_opensim(shared_data: Path, bridge) -> None:
    """da/dt of the controller's activation dynamics = OpenSim 4.6's DeGrooteFregly2016Muscle
    state derivative for all 18 muscles at random activations and excitations."""
    from nmsm.controllers.muscle import DGF_SMOOTHING, DGF_TIME_CONSTANTS, degroote_activation_derivative
    from nmsm.model import load_model

    path = shared_data.joinpath(*MODEL)
    model = load_model(path)
    names = [m.name for m in model.muscles]
    rng = np.random.default_rng(11)
    a = rng.uniform(0.01, 1, (8, len(names)))
    e = rng.uniform(0.01, 1, a.shape)
    e[0] = a[0]  # no change at e = a
    zeros = np.zeros((len(a), len(MUSCLE_COORDINATES)))
    ref = bridge.call("muscle_tendon_forces", model_file=str(path), coordinates=list(MUSCLE_COORDINATES), q=zeros,
                      u=zeros, activation=a, excitation=e)
    assert ref["names"] == names
    tau = [(float(model.muscle(m).properties.get("activation_time_constant", DGF_TIME_CONSTANTS[0])),
            float(model.muscle(m).properties.get("deactivation_time_constant", DGF_TIME_CONSTANTS[1]))) for m in names]
    tau_a, tau_d = (np.array(t) for t in zip(*tau))
    def rates(smoothing: float) -> np.ndarray:
        return np.array([np.asarray(degroote_activation_derivative(e[k], a[k], tau_a, tau_d, smoothing)).ravel()
                         for k in range(len(a))])

    expected = ref["activation_derivative"]
    assert np.abs(expected).max() > 10 and np.abs(expected[0]).max() == 0  # real rates (1/s); none at e = a
    assert np.allclose(rates(DGF_SMOOTHING), expected, rtol=1e-10, atol=1e-10)
    # the steepness of the switch matters: De Groote's b = 10 gives other rates
    assert np.abs(rates(10.0) - expected).max() > 1.0


def test_path_geometry_matches_full_model_geometry(shared_data: Path) -> None:
    from nmsm.controllers.muscle import PathGeometry
    from nmsm.model import load_model
    from nmsm.model.muscle_paths import PathMuscleGeometry

    model = load_model(shared_data.joinpath(*MODEL))
    geometry = PathGeometry(model, MUSCLE_COORDINATES)
    full = PathMuscleGeometry(model).function()
    rng = np.random.default_rng(8)
    names = model.coordinate_names
    for _ in range(3):
        q_all, qd_all = rng.uniform(-0.5, 0.5, len(names)), rng.normal(0, 1, len(names))
        cols = [names.index(c) for c in MUSCLE_COORDINATES]
        lengths, velocities, arms = (np.asarray(v) for v in geometry.function()(q_all[cols], qd_all[cols]))
        ref_l, _, ref_arms = (np.asarray(v) for v in full(q_all, qd_all))
        qd_only = np.zeros(len(names))
        qd_only[cols] = qd_all[cols]
        ref_v = np.asarray(full(q_all, qd_only)[1])
        # pelvis pose and lumbar do not change these muscles' lengths (no muscle crosses the lumbar joint)
        assert np.allclose(lengths, ref_l, atol=1e-12)
        assert np.allclose(velocities, ref_v, atol=1e-12)
        columns = [PathMuscleGeometry(model).coordinates.index(c) for c in MUSCLE_COORDINATES]
        assert np.allclose(arms, ref_arms[:, columns], atol=1e-12)


def test_settings_reader_parses_the_muscle_controller(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.tools.treatment.run import load_settings

    problem = write_problem(tmp_path / "w", shared_data / "moco2d", "muscle", mesh_intervals=4)
    settings, solver = load_settings(problem.settings)
    mc = settings.muscle_controller
    assert mc is not None and mc.muscle_force_model == "degroote2016"
    assert mc.surrogate_model_coordinate_list == MUSCLE_COORDINATES
    assert mc.surrogate_model_data_directory is None and mc.minimum_activation == 0.01
    assert settings.torque_controller.coordinate_list == ("lumbar",)


@pytest.mark.parametrize("mode", ["torque", "muscle"])
def test_problem_solves_on_a_coarse_mesh(shared_data: Path, tmp_path: Path, mode: str) -> None:
    data = shared_data / "moco2d"
    problem = write_problem(tmp_path / "w", data, mode, mesh_intervals=6, tolerance=1e-3)
    run = _solve(problem)
    assert run.solution.success, run.summary  # the tracked motion itself is not dynamically consistent:
    t, q, grf = read_solution(problem.results)
    assert set(q) == set(COORDINATES) and len(t) == 6 * 2 + 1
    err = tracking_error(data, t, q, grf)
    assert err.coordinates_deg < 5.0 and err.grf_n < 60.0
    if mode == "muscle":
        from nmsm.io.storage import read_storage

        act = read_storage(problem.results / "gait_combinedActivations.sto")
        # bounds hold on the collocation points; the last row (t_f) is the last interval's
        # control polynomial extrapolated by the transcription, which bounds do not constrain
        inner = act.data[:-1]
        assert len(act.labels) == 18 and inner.min() >= 0.01 - 1e-6 and inner.max() <= 1 + 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["torque", "muscle"])
def test_full_mesh_tracking_converges_and_tracks(shared_data: Path, tmp_path: Path, bridge, mode: str) -> None:
    """50 intervals, tolerance 1e-4, Moco's filtered reference: converges and tracks closely
    (bounds from our measured runs: docs/moco2d.md)."""
    from nmsm.examples.moco2d import states_reference_table
    data = shared_data / "moco2d"
    ref = states_reference_table(bridge, data)
    problem = write_problem(tmp_path / "w", data, mode, reference=ref)
    run = _solve(problem, constr_viol_tol=1e-4)
    assert run.solution.success, run.summary
    assert run.solution.iterations < 200
    t, q, grf = read_solution(problem.results)
    err = tracking_error(data, t, q, grf, ref)
    assert err.coordinates_deg < 3.0 and err.grf_n < 30.0


#: Moco 4.6's objectives of the anchors' runs (shared/anchors/RESULTS.md, items 1a and 2a)
MOCO_OBJECTIVE = {"torque": 0.469259, "muscle": 1.530373}


@pytest.mark.slow
@pytest.mark.parametrize("mode", ["torque", "muscle"])
def test_like_moco_problem_reaches_mocos_objective(shared_data: Path, tmp_path: Path, bridge, mode: str) -> None:
    """With Moco's activation dynamics, control periodicity and guess (``like_moco``), the
    50-interval problem is Moco's: our optimum's objective, in Moco's units, within -3 % / +1 %
    of Moco's own (measured: torque +0.14 %, muscle -0.95 %; the transcriptions differ,
    Radau vs Hermite-Simpson)."""
    from nmsm.examples.moco2d import states_reference_table
    data = shared_data / "moco2d"
    ref = states_reference_table(bridge, data)
    problem = write_problem(tmp_path / "w", data, mode, reference=ref, like_moco=True)
    run = _solve(problem, constr_viol_tol=1e-4)
    assert run.solution.success, run.summary
    objective = run.cost * problem.objective_factor
    assert 0.97 * MOCO_OBJECTIVE[mode] <= objective <= 1.01 * MOCO_OBJECTIVE[mode]
    t, q, grf = read_solution(problem.results)
    err = tracking_error(data, t, q, grf, ref)
    assert err.coordinates_deg < 3.0 and err.grf_n < 15.0


def test_settings_reader_parses_activation_dynamics(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.tools.treatment.run import load_settings

    problem = write_problem(tmp_path / "w", shared_data / "moco2d", "muscle", mesh_intervals=4, like_moco=True)
    settings, _ = load_settings(problem.settings)
    mc = settings.muscle_controller
    assert mc.activation_dynamics is True
    assert mc.activation_time_constant is None and mc.deactivation_time_constant is None
    plain = write_problem(tmp_path / "p", shared_data / "moco2d", "muscle", mesh_intervals=4)
    assert load_settings(plain.settings)[0].muscle_controller.activation_dynamics is False


def test_like_moco_muscle_problem_solves_with_activation_dynamics(shared_data: Path, tmp_path: Path) -> None:
    """Excitations as controls, activations as states: activations within their bounds at every
    node (the phase end too), periodic r<->l, and each activation follows its excitation by
    the DeGrooteFregly2016 dynamics (checked on the solution by collocation's own derivative)."""
    from nmsm.io.storage import read_storage
    data = shared_data / "moco2d"
    problem = write_problem(tmp_path / "w", data, "muscle", mesh_intervals=6, tolerance=1e-3, like_moco=True)
    run = _solve(problem)
    assert run.solution.success, run.summary
    act = read_storage(problem.results / "gait_combinedActivations.sto")
    exc = read_storage(problem.results / "gait_muscleExcitations.sto")
    assert act.labels == exc.labels and len(act.labels) == 18
    assert act.data.min() >= 0.01 - 1e-6 and act.data.max() <= 1 + 1e-6  # states: bounded at t_f too
    column = {m: j for j, m in enumerate(act.labels)}
    for m in act.labels:
        pair = m[:-2] + ("_l" if m.endswith("_r") else "_r")
        assert abs(act.data[-1, column[m]] - act.data[0, column[pair]]) <= 1e-4 + 1e-6
    # the activations lag the excitations (not equal to them)
    assert np.abs(act.data[:-1] - exc.data[:-1]).max() > 0.01
    # the phase dynamics give each activation state the derivative of its own muscle's excitation
    from nmsm.controllers.muscle import DGF_SMOOTHING, degroote_activation_derivative

    phase = run.prepared.built.trajectory.phase
    states, controls = phase.states.names, phase.controls.names
    assert states[-18:] == tuple(f"activation:{m}" for m in act.labels)
    rng = np.random.default_rng(2)
    x, u = rng.uniform(0.01, 1, len(states)), rng.uniform(0.01, 1, len(controls))
    dx = np.asarray(phase.dynamics(x, u, np.zeros(0))).ravel()
    a = x[[states.index(f"activation:{m}") for m in act.labels]]
    e = u[[controls.index(f"excitation:{m}") for m in act.labels]]
    expected = degroote_activation_derivative(e, a, 0.015, 0.060, DGF_SMOOTHING)  # the model's constants
    assert np.allclose(dx[-18:], np.asarray(expected).ravel(), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("mode", ["torque", "muscle"])
def test_like_moco_control_periodicity(shared_data: Path, tmp_path: Path, mode: str) -> None:
    """``controller_periodicity``: the lumbar control (and in torque mode the joint torques
    r<->l) end where their pair starts, as Moco's control pairs."""
    from nmsm.io.storage import read_storage
    problem = write_problem(tmp_path / "w", shared_data / "moco2d", mode, mesh_intervals=6, tolerance=1e-3,
                            like_moco=True)
    run = _solve(problem)
    assert run.solution.success, run.summary
    torques = read_storage(problem.results / "gait_torqueControls.sto")
    pairs = [("lumbar", "lumbar")]
    if mode == "torque":
        pairs += [(c, c[:-2] + ("_l" if c.endswith("_r") else "_r")) for c in MUSCLE_COORDINATES]
    for c, pair in pairs:
        end = torques.data[-1, torques.labels.index(_torque_label(torques.labels, c))]
        start = torques.data[0, torques.labels.index(_torque_label(torques.labels, pair))]
        assert abs(end - start) <= 1e-4 + 1e-6, (c, end, start)


def _torque_label(labels, coordinate):
    (label,) = [x for x in labels if x.startswith(coordinate)]
    return label


def test_activation_time_constants_come_from_settings_osimx_model_or_default(shared_data: Path) -> None:
    """Order: the settings' elements, the .osimx's personalized value (0.01 s units, τ_d = 4 τ_a),
    the muscle's .osim properties, DeGrooteFregly2016's defaults with a warning."""
    from types import SimpleNamespace

    from nmsm.controllers.muscle import _time_constants
    from nmsm.model import load_model

    model = load_model(shared_data.joinpath(*MODEL))  # every muscle has 0.015 / 0.060 s
    osimx = SimpleNamespace(muscles={"soleus_r": SimpleNamespace(activation_time_constant=2.5)})
    assert _time_constants({}, model, None, "soleus_r", "s.xml") == (0.015, 0.060)
    assert _time_constants({}, model, osimx, "soleus_r", "s.xml") == pytest.approx((0.025, 0.100), rel=1e-14)
    assert _time_constants({}, model, osimx, "tib_ant_r", "s.xml") == (0.015, 0.060)
    override = {"activation_time_constant": 0.02}
    assert _time_constants(override, model, osimx, "soleus_r", "s.xml") == pytest.approx((0.02, 0.100), rel=1e-14)
    bare = SimpleNamespace(muscle=lambda name: SimpleNamespace(properties={}))
    with pytest.warns(UserWarning, match="no deactivation_time_constant"):
        assert _time_constants({"activation_time_constant": 0.01}, bare, None, "m", "s.xml") == (0.01, 0.060)


def test_a_run_from_activation_dynamics_results_starts_from_their_excitations(shared_data: Path,
                                                                             tmp_path: Path) -> None:
    """A TO with activation dynamics writes its excitations; a run with its results as the
    initial guess starts its excitations there and tracks them with ``controller_tracking``
    (not the activations, which lag them), and reaches the same optimum."""
    import re

    from nmsm.io.storage import read_storage

    data = shared_data / "moco2d"
    to = write_problem(tmp_path / "to", data, "muscle", mesh_intervals=6, tolerance=1e-3, like_moco=True)
    first = _solve(to)
    assert first.solution.success
    excitations = read_storage(to.results / "gait_muscleExcitations.sto")
    activations = read_storage(to.results / "gait_combinedActivations.sto")
    assert np.abs(excitations.data - activations.data).max() > 0.05  # the two files differ
    warm_settings = tmp_path / "to" / "warm.xml"
    warm_settings.write_text(re.sub(r"<initial_guess_directory>[^<]*</initial_guess_directory>",
                                    f"<initial_guess_directory>{to.results}</initial_guess_directory>",
                                    to.settings.read_text()))
    run = _solve(attrs.evolve(to, settings=warm_settings, results=tmp_path / "warm_results"))
    assert run.solution.success
    assert run.cost <= first.cost * (1 + 1e-3)
    phase = run.prepared.built.trajectory.phase
    columns = [phase.controls.names.index(f"excitation:{m}") for m in excitations.labels]
    np.testing.assert_allclose(phase.controls.guess[:, columns], excitations.data[:-1], atol=1e-3)
    (controller,) = [c for c in run.prepared.built.data.controllers if c.type == "individual_muscle"]
    reference = controller.control_reference("excitation:soleus_r", excitations.time[:-1])
    np.testing.assert_allclose(reference.ravel(), excitations.data[:-1, excitations.labels.index("soleus_r")],
                               atol=1e-6)


def test_muscle_activations_start_at_the_default_guess_without_a_file(shared_data: Path, tmp_path: Path) -> None:
    """No ``<trial>_combinedActivations.sto`` in the initial-guess folder: every muscle's
    activation starts at the controller's documented default (0.1) at every collocation point."""
    from nmsm.tools.treatment.run import load_settings
    from nmsm.tools.treatment.tool import TreatmentOptions, prepare

    problem = write_problem(tmp_path / "w", shared_data / "moco2d", "muscle", mesh_intervals=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(problem.settings)
        built = prepare(settings, solver, TreatmentOptions()).built
    assert not list(Path(settings.initial_guess_directory).glob("*_combinedActivations.sto"))
    x0 = np.clip(built.problem.initial_scaled(), *built.problem.bounds_scaled())
    activations = np.asarray(built.problem.evaluate(cs.MX(built.context.muscle_activations()), x0))
    assert activations.shape[1] == 18
    np.testing.assert_allclose(activations, 0.1, rtol=0, atol=1e-12)  # the value docs/treatment.md states

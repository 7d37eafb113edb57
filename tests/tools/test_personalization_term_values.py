"""Known answers for model-personalization cost terms, their contexts and inputs (JMP, MTP,
MTLI, NCP, GCP), written out by hand from tools.md §1, §3-§6 and the cost catalog §2-§5.

Each test pins a value the 2023 unit tests and the tutorial runs do not reach (found by
mutation testing): a term or branch they never evaluate, a setting they leave at its
default, an error centre they leave at 0.
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import casadi as cs
import numpy as np
import pytest

from nmsm.core.registry import get_registry
from nmsm.errors import InputError


def _value(expression) -> np.ndarray:
    """Numeric value of a constant CasADi expression (or a numpy array) as a flat array."""
    if isinstance(expression, np.ndarray):
        return expression.ravel(order="F")
    return np.array(cs.evalf(cs.MX(expression))).ravel(order="F")


def _cost(term, ctx) -> float:
    """The term's objective contribution: the squared sum of its residuals."""
    return float(np.sum(_value(term.residuals(ctx)) ** 2))


def _term(tool: str, type_: str, **fields):
    return get_registry().get("cost", type_, tool)(**fields)


# ----------------------------------------------------------------------------------- MTP
def _mtp_context(lengths, initial=None, **kwargs):
    """An MtpContext whose trial models carry only normalized fiber lengths (n_frames, M)."""
    from nmsm.tools.mtp.context import MtpContext
    from nmsm.tools.mtp.model import MuscleDesign
    from nmsm.tools.mtp.muscles import MuscleParameters

    m = lengths[0].shape[1]
    muscles = MuscleParameters([f"m{i}" for i in range(m)], np.full(m, 1000.0), np.full(m, 0.1), np.full(m, 0.2),
                               np.zeros(m))
    models = [SimpleNamespace(normalized_fiber_length=cs.MX(cs.DM(l))) for l in lengths]
    return MtpContext(
        muscles=muscles, design=MuscleDesign.initial(m), models=models, synx_models=None,
        inverse_dynamics_moments=[], initial_fiber_length=list(initial if initial is not None else lengths),
        activation_groups=(), fiber_length_groups=(), measured=tuple(range(m)), missing=(), padding=0,
        **kwargs)


def test_mtp_initial_design_is_the_spec_table():
    """tools.md §4.3 initial values: EMD 0.5 (0.1 s), activation time constant 1.5 (0.01 s),
    A 0.05, EMG scale 0.5, length scale factors 1."""
    from nmsm.tools.mtp.model import MuscleDesign

    d = MuscleDesign.initial(3)
    assert np.array_equal(d.electromechanical_delay, [0.5] * 3)
    assert np.array_equal(d.activation_time_constant, [1.5] * 3)
    assert np.array_equal(d.activation_nonlinearity, [0.05] * 3)
    assert np.array_equal(d.emg_scale, [0.5] * 3)
    assert np.array_equal(d.optimal_fiber_length_scale, [1.0] * 3)
    assert np.array_equal(d.tendon_slack_length_scale, [1.0] * 3)


def test_mtp_minimum_normalized_fiber_length_penalizes_the_shortfall_of_the_minimum():
    """``min(min_t l - l_min, 0)`` per trial and muscle, reduced as sum(z^2)/numel: the
    deviation beyond the limit (a deliberate departure from the original's value-where-below,
    docs/mtp.md "Departures from the original")."""
    lengths = [np.array([[0.70, 0.90], [0.80, 0.95], [0.90, 1.20]]),
               np.array([[0.74, 0.60], [1.00, 0.80], [1.10, 0.85]])]
    ctx = _mtp_context(lengths, min_normalized_fiber_length=0.75, max_normalized_fiber_length=1.05)
    term = _term("MTP", "minimum_normalized_muscle_fiber_length", max_allowable_error=0.1)
    # minima (trial x muscle): [[0.70, 0.90], [0.74, 0.60]] -> shortfalls -0.05, 0, -0.01, -0.15
    expected = np.array([-0.05, 0.0, -0.01, -0.15]) / 0.1
    assert _cost(term, ctx) == pytest.approx(np.mean(expected**2), rel=1e-12)


def test_mtp_maximum_normalized_fiber_length_penalizes_the_excess_of_the_maximum():
    """``max(max_t l - l_max, 0)`` per trial and muscle, task maximum 1.05 (the same
    deliberate departure as the minimum term)."""
    lengths = [np.array([[0.70, 0.90], [0.80, 0.95], [0.90, 1.20]]),
               np.array([[0.74, 0.60], [1.10, 0.80], [1.00, 0.85]])]
    ctx = _mtp_context(lengths, min_normalized_fiber_length=0.75, max_normalized_fiber_length=1.05)
    term = _term("MTP", "maximum_normalized_muscle_fiber_length", max_allowable_error=0.1)
    # maxima [[0.90, 1.20], [1.10, 0.85]] -> excesses 0, 0.15, 0.05, 0
    expected = np.array([0.0, 0.15, 0.05, 0.0]) / 0.1
    assert _cost(term, ctx) == pytest.approx(np.mean(expected**2), rel=1e-12)


def test_mtp_normalized_fiber_length_blocks_subtract_the_error_center():
    """Magnitude and shape blocks each contribute sum(((x - c)/e)^2)/numel with c != 0."""
    rng = np.random.default_rng(5)
    initial = [rng.uniform(0.8, 1.1, (4, 2)) for _ in range(2)]
    model = [l + rng.normal(0.0, 0.03, l.shape) for l in initial]
    ctx = _mtp_context(model, initial)
    e, c = 0.1, 0.02
    term = _term("MTP", "normalized_muscle_fiber_length", max_allowable_error=e, error_center=c)
    magnitude = (model[0] + model[1]) / 2 - (initial[0] + initial[1]) / 2
    mod, ini = np.vstack(model), np.vstack(initial)
    shape = (mod - mod.mean(axis=0)) - (ini - ini.mean(axis=0))
    expected = np.mean(((magnitude - c) / e) ** 2) + np.mean(((shape - c) / e) ** 2)
    assert _cost(term, ctx) == pytest.approx(expected, rel=1e-12)


def test_muscle_parameters_reject_a_pennation_of_90_degrees_and_a_zero_force():
    """Pennation must lie in [0, pi/2) and F0 > 0 (cos(pi/2) = 0 would divide by zero)."""
    from nmsm.tools.mtp.muscles import MuscleParameters

    good = dict(names=["a"], max_isometric_force=[100.0], optimal_fiber_length=[0.1], tendon_slack_length=[0.2],
                pennation_angle=[np.pi / 2 - 1e-9])
    MuscleParameters(**good)
    with pytest.raises(InputError, match="pennation_angle"):
        MuscleParameters(**{**good, "pennation_angle": [np.pi / 2]})
    with pytest.raises(InputError, match="max_isometric_force"):
        MuscleParameters(**{**good, "max_isometric_force": [0.0]})


def test_channel_map_refuses_a_muscle_in_the_first_and_another_channel():
    """A muscle in two collected EMG channel groups is an error, channel 0 included."""
    from nmsm.tools.mtp.muscles import MuscleGroup, channel_map

    names = ["a", "b", "c"]
    assert list(channel_map(names, [MuscleGroup("g0", (0, 1)), MuscleGroup("g1", (2,))], [])) == [0, 0, 1]
    with pytest.raises(InputError, match="'b' is in two EMG channel groups"):
        channel_map(names, [MuscleGroup("g0", (0, 1)), MuscleGroup("g1", (1, 2))], [])


def test_resolve_groups_drops_an_empty_group_only_when_asked():
    from nmsm.tools.mtp.muscles import MuscleGroup, resolve_groups

    model_groups = {"knee": ["b", "a"], "hip": ["z"]}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dropped = resolve_groups(["knee", "hip"], model_groups, ["a", "b"], setting="s")
        kept = resolve_groups(["knee", "hip"], model_groups, ["a", "b"], setting="s", drop_empty=False)
    assert dropped == (MuscleGroup("knee", (1, 0)),)
    assert kept == (MuscleGroup("knee", (1, 0)), MuscleGroup("hip", ()))


# ----------------------------------------------------------------------------------- MTLI
def _mtli_context(absolute: bool, lo_variable, lts_variable):
    from nmsm.tools.mtp.mtli_model import MtliContext
    from nmsm.tools.mtp.muscles import MuscleParameters

    muscles = MuscleParameters(["a", "b", "c"], [500.0, 800.0, 300.0], [0.10, 0.08, 0.12], [0.25, 0.30, 0.20],
                               [0.0, 0.1, 0.2])
    return MtliContext(muscles, absolute, cs.DM(lo_variable), cs.DM(lts_variable), cs.DM([1.0]), 1.0,
                       np.zeros(3, dtype=int), [], [], [], (), (), 0.6, 1.0)


@pytest.mark.parametrize("type_, lo, lts, expected", [
    ("optimal_muscle_fiber_length", [0.11, 0.08, 0.10], [0.25, 0.30, 0.20], [0.01, 0.0, -0.02]),
    ("tendon_slack_length", [0.10, 0.08, 0.12], [0.24, 0.33, 0.20], [-0.01, 0.03, 0.0]),
])
def test_mtli_length_terms_in_absolute_mode_are_changes_in_metres(type_, lo, lts, expected):
    """``optimize_absolute_length_changes``: x = l - l_model (m), residuals (x - c)/(e sqrt(n))."""
    ctx = _mtli_context(True, lo, lts)
    e, c = 0.05, 0.005
    term = _term("MTLI", type_, max_allowable_error=e, error_center=c)
    residuals = _value(term.residuals(ctx))
    np.testing.assert_allclose(residuals, (np.array(expected) - c) / (e * np.sqrt(3)), rtol=1e-12, atol=1e-15)


# ----------------------------------------------------------------------------------- NCP
def _ncp_inputs(v_max_factor: float = 10.0):
    """Two synergy groups, right (a_r, b_r, c_r) and left listed in another order (b_l, a_l,
    c_l); one coordinate, three frames, made-up muscle data."""
    from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters
    from nmsm.tools.ncp.inputs import NcpInputs, NcpTrial
    from nmsm.tools.ncp.synergies import SynergyGroup, SynergyLayout

    layout = SynergyLayout([SynergyGroup("right", ["a_r", "b_r", "c_r"], 2),
                            SynergyGroup("left", ["b_l", "a_l", "c_l"], 2)], n_nodes=21)
    names = list(layout.muscles)
    muscles = MuscleParameters(names, [1000.0, 800.0, 600.0, 800.0, 1000.0, 600.0], [0.10, 0.08, 0.12, 0.08, 0.10, 0.12],
                               [0.25, 0.30, 0.20, 0.30, 0.25, 0.20], [0.0, 0.2, 0.1, 0.2, 0.0, 0.1])
    lengths = np.array([[0.35, 0.385, 0.33, 0.38, 0.36, 0.32],
                        [0.36, 0.375, 0.335, 0.39, 0.35, 0.325],
                        [0.345, 0.38, 0.325, 0.385, 0.355, 0.33]])
    velocities = np.array([[0.2, -0.1, 0.05, 0.1, -0.3, 0.0],
                           [-0.25, 0.15, -0.05, 0.0, 0.2, 0.1],
                           [0.1, 0.0, 0.3, -0.2, 0.05, -0.15]])
    arms = np.full((3, 1, 6), 0.03)
    trial = NcpTrial("t", np.arange(3.0), lengths, velocities, arms, np.zeros((3, 1)))
    return NcpInputs(layout=layout, coordinates=["q"], trials=[trial], muscles=muscles,
                     activation_groups=[MuscleGroup("g", (0, 1, 4))], v_max_factor=v_max_factor)


def test_ncp_moment_gains_use_the_settings_maximum_fiber_velocity():
    """Active gain ``r F0 f_L(l) f_V(V / (vmax l_o cos a)) cos a`` with vmax = 5 l_o/s (not 10)."""
    from nmsm.model import hill
    from nmsm.tools.ncp.forces import moment_gains

    inputs = _ncp_inputs(v_max_factor=5.0)
    trial, m = inputs.trials[0], inputs.muscles
    gains = moment_gains(trial, m, inputs.v_max_factor)
    cos_a = np.cos(m.pennation_angle)
    length = (trial.lengths - m.tendon_slack_length) / (m.optimal_fiber_length * cos_a)
    velocity = trial.velocities / (5.0 * m.optimal_fiber_length * cos_a)
    active = m.max_isometric_force * hill.active_force_length(length) * hill.force_velocity(velocity) * cos_a
    np.testing.assert_allclose(gains.active[:, 0, :], 0.03 * active, rtol=1e-12)


@pytest.mark.parametrize("symbolic", [False, True])
def test_ncp_grouped_activations_subtract_the_group_mean_per_frame(symbolic):
    """``a - mean over the group`` per frame (catalog §4), numeric and CasADi paths alike."""
    from nmsm.tools.ncp.context import NcpContext

    inputs = _ncp_inputs()
    a = np.array([[0.1, 0.2, 0.9, 0.5, 0.6, 0.0],
                  [0.3, 0.0, 0.8, 0.5, 0.3, 0.1],
                  [0.2, 0.4, 0.7, 0.5, 0.9, 0.2]])
    ctx = NcpContext(inputs, [np.zeros((2, 3))] * 2, [cs.DM(a) if symbolic else a], gains=[])
    e, c = 0.2, 0.01
    term = _term("NCP", "grouped_activations", max_allowable_error=e, error_center=c)
    block = a[:, [0, 1, 4]]
    deviation = (block - block.mean(axis=1, keepdims=True)).ravel(order="F")
    np.testing.assert_allclose(_value(term.residuals(ctx)), (deviation - c) / e / np.sqrt(9), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("symbolic", [False, True])
def test_ncp_bilateral_symmetry_compares_each_muscle_with_its_mirror(symbolic):
    """``W_right - W_left`` with left columns reordered to the right's muscles by name:
    the left group lists b_l, a_l, c_l, so a_r pairs with column 1, b_r with column 0."""
    from nmsm.tools.ncp.context import NcpContext

    inputs = _ncp_inputs()
    w1 = np.array([[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]])
    w2 = np.array([[0.25, 0.05, 0.3], [0.5, 0.35, 0.65]])
    blocks = [cs.DM(w1), cs.DM(w2)] if symbolic else [w1, w2]
    ctx = NcpContext(inputs, blocks, [np.zeros((3, 6))], gains=[])
    term = _term("NCP", "bilateral_symmetry", max_allowable_error=0.01)
    expected = (w1 - w2[:, [1, 0, 2]]).ravel(order="F")  # [[0.05, -0.05, 0], [0.05, 0, -0.05]]
    np.testing.assert_allclose(_value(term.residuals(ctx)), expected / 0.01 / np.sqrt(6), rtol=1e-12, atol=1e-12)


def test_ncp_synergy_weight_sum_is_zero_when_each_vector_sums_to_a_hundredth_per_muscle():
    """tools.md §5: every synergy vector of group g sums to M_g/100 (3 muscles: 0.03)."""
    from nmsm.constraints.ncp.synergy_weight_sum import SynergyWeightSum
    from nmsm.tools.ncp.context import NcpContext

    inputs = _ncp_inputs()
    w2 = np.array([[0.01, 0.015, 0.005], [0.02, 0.0, 0.02]])
    ctx = NcpContext(inputs, [np.zeros((2, 3)), w2], [np.zeros((3, 6))], gains=[])
    group = inputs.layout.groups[1]
    assert group.weight_sum == pytest.approx(0.03)
    value, lower, upper = SynergyWeightSum(group=1, target=group.weight_sum).bounded(ctx)
    np.testing.assert_allclose(value, [0.0, 0.01], atol=1e-15)
    assert (lower, upper) == (0.0, 0.0)


# ----------------------------------------------------------------------------------- GCP
@pytest.fixture(scope="module")
def gcp_scene(tmp_path_factory):
    """The synthetic GCP case at a state with every quantity away from its initial value:
    kinematic coefficients, spring constants, an electrical-center shift and a plate
    rotation. Returns (feet, state, context)."""
    from nmsm.examples.synthetic_gcp import write_synthetic_gcp
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.context import GcpContext
    from nmsm.tools.gcp.run import load_feet
    from nmsm.tools.gcp.state import GcpState
    from nmsm.tools.gcp.values import foot_values

    case = write_synthetic_gcp(tmp_path_factory.mktemp("gcp_term_values"))
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(case.settings_file))
    feet = load_feet(settings)[0]
    state = GcpState.initial(settings, feet)
    rng = np.random.default_rng(11)
    state.spring_constants = rng.uniform(1500.0, 4000.0, feet[0].springs.n_springs)
    state.coefficients = [1.0 + rng.normal(0.0, 0.02, c.shape) for c in state.coefficients]
    state.electrical_center_shifts = [np.array([0.004, -0.002, 0.007]) for _ in feet]
    state.plate_rotations = [0.05 for _ in feet]
    design = state.design()
    values = [foot_values(foot, design, i) for i, foot in enumerate(feet)]
    return feet, state, GcpContext(feet, values, design, 0.05)


def _gcp_cost(ctx, type_, e, c=0.0, **fields):
    return _cost(_term("GCP", type_, max_allowable_error=e, error_center=c, **fields), ctx)


def _per_foot(blocks, e, c=0.0):
    """Catalog §5: each foot's residual raw/(e sqrt(len)), i.e. the mean of ((raw - c)/e)^2 per foot."""
    return sum(np.mean(((np.asarray(b, dtype=float) - c) / e) ** 2) for b in blocks)


def test_gcp_rotation_and_translation_split_the_seven_foot_coordinates(gcp_scene):
    """rotation: q(1:4) - q_exp(1:4) (toe angle and three rotations); translation: q(5:7) - q_exp(5:7)."""
    from nmsm.tools.gcp.values import as_array

    feet, _, ctx = gcp_scene
    errors = [as_array(v.coordinates) - f.coordinates.T for f, v in zip(feet, ctx.values)]
    assert min(np.abs(err[4:7]).max() for err in errors) > 1e-5  # the state moved every coordinate
    assert _gcp_cost(ctx, "rotation", 0.01, 0.001) == pytest.approx(
        _per_foot([err[0:4] for err in errors], 0.01, 0.001), rel=1e-10)
    assert _gcp_cost(ctx, "translation", 0.002, 0.0002) == pytest.approx(
        _per_foot([err[4:7] for err in errors], 0.002, 0.0002), rel=1e-10)


def test_gcp_kinematic_periodicity_is_normalized_by_the_experimental_change_or_its_floor(gcp_scene):
    """(q(t0) - q(tf)) ./ max(|q_exp(t0) - q_exp(tf)|, [0.0175 x4, 0.001 x3]) (catalog §5)."""
    from nmsm.tools.gcp.values import as_array

    feet, _, ctx = gcp_scene
    blocks = []
    for f, v in zip(feet, ctx.values):
        q = as_array(v.coordinates)
        scale = np.maximum(np.abs(f.coordinates[0] - f.coordinates[-1]), [0.0175] * 4 + [0.001] * 3)
        blocks.append((q[:, 0] - q[:, -1]) / scale)
    assert _gcp_cost(ctx, "kinematic_periodicity", 0.5) == pytest.approx(_per_foot(blocks, 0.5), rel=1e-10)


def test_gcp_force_and_moment_terms_compare_the_right_components(gcp_scene):
    """vertical_grf row y, horizontal_grf rows x and z, ground_reaction_moment all three, modeled
    minus experimental (after the shift and plate rotation)."""
    from nmsm.tools.gcp.values import as_array

    feet, _, ctx = gcp_scene
    force = [as_array(v.forces) - as_array(v.experimental_forces) for v in ctx.values]
    moment = [as_array(v.moments) - as_array(v.experimental_moments) for v in ctx.values]
    assert _gcp_cost(ctx, "vertical_grf", 5.0, 1.0) == pytest.approx(_per_foot([f[1] for f in force], 5.0, 1.0),
                                                                      rel=1e-10)
    assert _gcp_cost(ctx, "horizontal_grf", 2.0) == pytest.approx(_per_foot([f[[0, 2]] for f in force], 2.0),
                                                                   rel=1e-10)
    assert _gcp_cost(ctx, "ground_reaction_moment", 1.5) == pytest.approx(_per_foot(moment, 1.5), rel=1e-10)


def test_gcp_slope_terms_use_25_nodes_for_modeled_and_the_foot_nodes_for_experimental_curves(gcp_scene):
    """tools.md §6.4: degree-2 B-spline derivatives, the foot's node count for experimental
    curves and 25 nodes for modeled ones."""
    from nmsm.tools.gcp.bspline import derivative_matrix
    from nmsm.tools.gcp.values import as_array

    feet, _, ctx = gcp_scene
    force_blocks, moment_blocks = [], []
    for f, v in zip(feet, ctx.values):
        modeled_op = derivative_matrix(f.time, 2, 25)
        experimental_op = derivative_matrix(f.time, 2, f.n_nodes)
        force_blocks.append(as_array(v.forces)[[0, 2]] @ modeled_op.T
                            - as_array(v.experimental_forces)[[0, 2]] @ experimental_op.T)
        moment_blocks.append(as_array(v.moments) @ modeled_op.T - as_array(v.experimental_moments) @ experimental_op.T)
    assert feet[0].n_nodes != 25 and feet[0].time.size > 25
    assert _gcp_cost(ctx, "horizontal_grf_slope", 50.0) == pytest.approx(_per_foot(force_blocks, 50.0), rel=1e-10)
    assert _gcp_cost(ctx, "ground_reaction_moment_slope", 20.0) == pytest.approx(_per_foot(moment_blocks, 20.0),
                                                                                 rel=1e-10)


def test_gcp_regularization_terms(gcp_scene):
    """spring_constant_mean: K - mean(K), one block per foot; electrical_center_regularization
    along the chosen axes only; force_plate_rotation_regularization: the angle."""
    feet, state, ctx = gcp_scene
    k = state.spring_constants
    n_feet = len(feet)
    assert _gcp_cost(ctx, "spring_constant_mean", 500.0) == pytest.approx(
        n_feet * np.mean(((k - k.mean()) / 500.0) ** 2), rel=1e-12)
    shifts = state.electrical_center_shifts
    assert _gcp_cost(ctx, "electrical_center_regularization", 0.01, axes="x z") == pytest.approx(
        _per_foot([s[[0, 2]] for s in shifts], 0.01), rel=1e-12)
    assert _gcp_cost(ctx, "electrical_center_regularization", 0.01) == pytest.approx(_per_foot(shifts, 0.01), rel=1e-12)
    assert _gcp_cost(ctx, "force_plate_rotation_regularization", 0.1) == pytest.approx(n_feet * 0.25, rel=1e-12)


def test_gcp_experimental_reactions_move_to_the_resting_height_shift_and_rotate_about_y():
    """tools.md §6.4: M = M_mid + ((0, -L0, 0) + shift) x F, then F and M rotated by
    R = [[c, 0, s], [0, 1, 0], [-s, 0, c]] (rotation about ground y by theta)."""
    from nmsm.tools.gcp.values import as_array, experimental_reactions

    forces = np.array([[10.0, 700.0, -20.0], [30.0, 500.0, 5.0]])
    moments = np.array([[1.0, 2.0, -3.0], [-0.5, 0.25, 4.0]])
    foot = SimpleNamespace(reactions=SimpleNamespace(forces=forces), plate_moments_about_midfoot=moments)
    rest, shift, theta = 0.02, np.array([0.01, -0.003, 0.004]), 0.1
    f, m = experimental_reactions(foot, rest, cs.DM(shift), theta)
    c, s = np.cos(theta), np.sin(theta)
    rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    lever = np.array([0.0, -rest, 0.0]) + shift
    expected_m = (moments + np.cross(lever, forces)) @ rotation.T
    np.testing.assert_allclose(as_array(f).T, forces @ rotation.T, rtol=1e-14, atol=1e-12)
    np.testing.assert_allclose(as_array(m).T, expected_m, rtol=1e-14, atol=1e-12)
    # an anterior force turned by +0.1 rad about y gains a negative z component
    f1, _ = experimental_reactions(SimpleNamespace(reactions=SimpleNamespace(forces=np.array([[100.0, 0.0, 0.0]])),
                                                   plate_moments_about_midfoot=np.zeros((1, 3))), 0.0, cs.DM.zeros(3), theta)
    np.testing.assert_allclose(as_array(f1).ravel(), [100.0 * c, 0.0, -100.0 * s], rtol=1e-14)


# ----------------------------------------------------------------------------------- JMP
@pytest.fixture(scope="module")
def jmp_task(tmp_path_factory):
    """The synthetic leg's first task: (model, marker trial, kinematics, design, initial q)."""
    from nmsm.examples.synthetic_jmp import make_synthetic_jmp_case
    from nmsm.io.trc import read_trc
    from nmsm.model import load_model
    from nmsm.tools.jmp.design import build_design
    from nmsm.tools.jmp.ik import inverse_kinematics
    from nmsm.tools.jmp.marker_data import select_trial
    from nmsm.tools.jmp.marker_model import MarkerKinematics
    from nmsm.tools.jmp.run import read_settings

    case = make_synthetic_jmp_case(tmp_path_factory.mktemp("jmp_values"), noise=0.0005, duration=0.3)
    settings = read_settings(case.settings_file)
    task = settings.tasks[0]
    model = load_model(settings.input_model_file)
    table = read_trc(task.marker_file_name)
    design = build_design(model, task, table.names)
    trial = select_trial(table, model, {m: 1.0 for m in design.marker_names})
    kin = MarkerKinematics(model, trial.names, design.parameters)
    ik = inverse_kinematics(model, trial, kinematics=kin, parameters=design.parameters)
    q0 = ik.q[:, [ik.coordinate_names.index(n) for n in kin.free_names]]
    return trial, kin, design, q0


def test_jmp_marker_cost_is_the_weighted_mean_square_distance_over_observations(jmp_task):
    """``sum_f sum_m w_m |x_m(q_f, p) - x_exp|^2 / (n_obs e^2)``, gaps excluded (JMP term
    docstring; tools.md §1 ``r = d/sqrt(M)/sqrt(F)/e`` without gaps), with unequal weights."""
    import attrs

    from nmsm.terms.jmp.marker_distance import MarkerDistanceError
    from nmsm.tools.jmp.problem import JmpProblem

    trial, kin, design, q0 = jmp_task
    weights = np.linspace(0.5, 3.0, trial.n_markers)
    positions = trial.positions.copy()
    positions[2:5, 1] = np.nan  # a gap of three frames in the second marker
    trial = attrs.evolve(trial, weights=weights, positions=positions)
    p0 = design.initial + 0.01  # away from the nominal model
    e = 0.01
    problem = JmpProblem(kin, trial, [MarkerDistanceError(max_allowable_error=e)], design.lower, design.upper)
    modeled = kin.marker_positions(q0, p0)
    squared = np.nansum((modeled - positions) ** 2, axis=2)  # (F, M), gaps 0
    n_obs = trial.n_frames * trial.n_markers - 3
    expected = float(np.sum(squared * weights[None, :])) / (n_obs * e**2)
    assert problem.term_costs(q0, p0)["marker_distance_error"] == pytest.approx(expected, rel=1e-10)


def test_jmp_task_without_marker_observations_is_an_input_error(jmp_task):
    import attrs

    from nmsm.terms.jmp.marker_distance import MarkerDistanceError
    from nmsm.tools.jmp.problem import JmpProblem

    trial, kin, design, _ = jmp_task
    empty = attrs.evolve(trial, positions=np.full_like(trial.positions, np.nan))
    with pytest.raises(InputError, match="no marker observation"):
        JmpProblem(kin, empty, [MarkerDistanceError(max_allowable_error=0.01)], design.lower, design.upper)

"""Exact path-point muscle geometry against OpenSim (through the bridge).

Lengths must equal OpenSim's path lengths (<= 1e-9 m); moment arms ``-dL/dq`` (CasADi AD,
couplers included) must equal central differences of OpenSim path lengths with the
coupler assembled (<= 1e-6 m); OpenSim's ``computeMomentArm`` is compared separately.
Poses are random within each coordinate's range (rotations limited to ±1.5 rad), so
ConditionalPathPoints switch and MovingPathPoints move.
"""

from __future__ import annotations

import csv

import casadi as cs
import numpy as np
import pytest

from nmsm.errors import ModelError
from nmsm.model import load_model
from nmsm.model.muscle_paths import PathMuscleGeometry, evaluate_function, has_active_wrapping

LENGTH_TOLERANCE = 1e-9  # m
MOMENT_ARM_TOLERANCE = 1e-6  # m

#: a default-suite subset: every path-point kind, a coupler, muscles under <components>, old file formats
QUICK_MODELS = (
    "treatment/surrogate_kick_tutorial/RightLegAndPelvis.osim",
    "jmp/gait2392_walk_free/subject01_gait2392_scaled.osim",  # ConditionalPathPoint, MovingPathPoint, v20303
    "opensim_gait10dof18musc/gait10dof18musc_subject01.osim",  # v30000
    "moco2d/2D_gait.osim",  # muscles under <components>
    "models/RCNL2024.osim",  # 86 muscles, two patella couplers
    "core/nmsm_core_tests/model/arm26.osim",  # wrap ellipsoids/cylinders
)


def _models_with_muscles(shared_data) -> list[str]:
    with open(shared_data / "OSIM_CHECK.tsv") as fh:
        return [r["path"] for r in csv.DictReader(fh, delimiter="\t") if int(r["muscles"]) > 0]


def _random_poses(model, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo = np.array([max(c.range[0], -1.5) for c in model.coordinates])
    hi = np.array([min(c.range[1], 1.5) for c in model.coordinates])
    return lo + rng.random((n, len(lo))) * (hi - lo)


def _check_model(path, bridge, n_poses: int = 8) -> dict[str, float]:
    model = load_model(path)
    geometry = PathMuscleGeometry(model)
    assert geometry.muscles, f"{path}: no path-point muscle"
    q = _random_poses(model, n_poses, seed=0)
    lengths, _, arms = evaluate_function(geometry.function(), q)
    ref = bridge.call("muscle_length_gradients", model=str(path), q=q, coordinates=model.coordinate_names,
                      muscles=list(geometry.muscles), wrt=list(geometry.coordinates))
    osim_arms = bridge.call("muscle_moment_arms", model=str(path), q=q, coordinates=model.coordinate_names,
                            muscles=list(geometry.muscles), moment_arm_coordinates=list(geometry.coordinates))
    length_error = np.abs(lengths - ref["lengths"]).max()
    arm_error = np.abs(arms + ref["gradient"]).max()
    assert length_error <= LENGTH_TOLERANCE, f"{path}: length error {length_error:.3g} m"
    assert arm_error <= MOMENT_ARM_TOLERANCE, f"{path}: moment-arm error {arm_error:.3g} m"
    # no coupler acts on a path-point muscle here: OpenSim's computeMomentArm is -dL/dq too
    assert np.abs(arms - osim_arms).max() <= MOMENT_ARM_TOLERANCE
    return {"muscles": len(geometry.muscles), "length": length_error, "moment_arm": arm_error,
            "compute_moment_arm": float(np.abs(arms - osim_arms).max())}


@pytest.mark.parametrize("relative", QUICK_MODELS)
def test_path_point_muscles_match_opensim(shared_data, bridge, relative, record_property) -> None:
    figures = _check_model(shared_data / relative, bridge)
    for key, value in figures.items():
        record_property(key, value)


@pytest.mark.slow
def test_every_shared_model_with_muscles(shared_data, bridge) -> None:
    checked = []
    for relative in _models_with_muscles(shared_data):
        path = shared_data / relative
        if not PathMuscleGeometry(load_model(path)).muscles:
            continue
        checked.append((relative, _check_model(path, bridge, n_poses=5)))
    assert len(checked) >= 20
    for relative, fig in checked:
        print(f"{relative}: {fig['muscles']} muscles, length {fig['length']:.1e} m, moment arm {fig['moment_arm']:.1e} m")


def test_conditional_points_switch_within_the_sampled_poses(shared_data) -> None:
    """The gait2392 check above is meaningful only if its ConditionalPathPoints do switch."""
    from nmsm.model.components import ConditionalPathPoint

    model = load_model(shared_data / "jmp/gait2392_walk_free/subject01_gait2392_scaled.osim")
    q = _random_poses(model, 8, seed=0)
    states = set()
    for muscle in model.muscles:
        for point in muscle.geometry.points:
            if isinstance(point, ConditionalPathPoint):
                v = q[:, model.coordinate_index(point.coordinate)]
                inside = (v >= point.range[0] - 1e-5) & (v <= point.range[1] + 1e-5)
                states.update(inside.tolist())
    assert states == {True, False}


def test_velocity_is_the_time_derivative_of_length(shared_data) -> None:
    model = load_model(shared_data / "opensim_gait10dof18musc/gait10dof18musc_subject01.osim")
    f = PathMuscleGeometry(model).function()
    q0 = _random_poses(model, 1, seed=3)[0]
    qdot = np.random.default_rng(4).normal(size=q0.size)
    h = 1e-6
    velocity = np.asarray(f(q0, qdot)[1]).ravel()
    fd = (np.asarray(f(q0 + h * qdot, qdot)[0]) - np.asarray(f(q0 - h * qdot, qdot)[0])).ravel() / (2 * h)
    np.testing.assert_allclose(velocity, fd, atol=1e-8)


def test_coupled_coordinate_enters_through_its_coupler(shared_data, bridge) -> None:
    """Dependent entries of q are ignored; the knee moment arm includes the patella chain."""
    path = shared_data / "treatment/surrogate_kick_tutorial/RightLegAndPelvis.osim"
    model = load_model(path)
    geometry = PathMuscleGeometry(model, muscles=["bflh_r", "vasmed_r"], allow_wrapping=True)
    f = geometry.function()
    q = _random_poses(model, 1, seed=1)[0]
    beta = model.coordinate_index("knee_angle_r_beta")
    other = q.copy()
    other[beta] += 0.3
    assert np.array_equal(np.asarray(f(q, np.zeros_like(q))[0]), np.asarray(f(other, np.zeros_like(q))[0]))
    assert "knee_angle_r_beta" not in geometry.coordinates
    # vasmed_r lies on the patella only: its knee moment arm is entirely the coupler's chain rule
    k = geometry.coordinates.index("knee_angle_r")
    assert abs(float(f(q, np.zeros_like(q))[2][1, k])) > 1e-3


def test_wrapping_muscles_are_refused_unless_allowed(shared_data) -> None:
    model = load_model(shared_data / "treatment/surrogate_kick_tutorial/RightLegAndPelvis.osim")
    assert has_active_wrapping(model, model.muscle("gasmed_r"))
    assert not has_active_wrapping(model, model.muscle("soleus_r"))
    assert PathMuscleGeometry(model).muscles == ("bflh_r", "soleus_r", "tibant_r")
    with pytest.raises(ModelError, match="gasmed_r"):
        PathMuscleGeometry(model, muscles=["gasmed_r"])
    with pytest.raises(ModelError, match="knee_angle_r_beta"):
        PathMuscleGeometry(model, coordinates=["knee_angle_r_beta"])


def test_lengths_work_inside_an_mx_graph(shared_data) -> None:
    model = load_model(shared_data / "moco2d/2D_gait.osim")
    f = PathMuscleGeometry(model).function()
    q = cs.MX.sym("q", len(model.coordinates), 4)
    out = f.map(4)(q, cs.MX.zeros(q.shape))
    g = cs.Function("g", [q], [cs.jacobian(cs.vec(out[0]), cs.vec(q))])
    jac = np.asarray(g(np.tile(_random_poses(model, 1, 0).T, (1, 4))))
    assert jac.shape == (18 * 4, len(model.coordinates) * 4) and np.isfinite(jac).all()

"""Inverse kinematics: exact recovery on synthetic data, gaps, couplers, units, files, CLI."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.examples.synthetic_jmp import leg_model_xml
from nmsm.io.storage import read_storage
from nmsm.io.trc import MarkerTable, write_trc
from nmsm.model import load_model
from nmsm.tools.jmp.ik import inverse_kinematics, run_ik_files
from nmsm.tools.jmp.ik_settings import read_ik_settings
from nmsm.tools.jmp.marker_model import MarkerKinematics

TUTORIAL = "jmp/uf_subject3_tutorial"


@pytest.fixture(scope="module")
def leg(tmp_path_factory):
    """The built-in leg model, a known motion (rad / m) and its exact markers (m)."""
    folder = tmp_path_factory.mktemp("leg")
    path = folder / "leg.osim"
    path.write_bytes(leg_model_xml())
    model = load_model(path)
    kin = MarkerKinematics(model, model.marker_names)
    time = np.linspace(0.0, 1.0, 51)
    q = np.column_stack([0.3 * np.sin(2 * np.pi * (0.5 + 0.2 * k) * time + k) for k in range(kin.n_free)])
    knee = kin.free_names.index("knee_angle")
    q[:, knee] = -0.9 + 0.7 * np.sin(2 * np.pi * time)  # inside the clamped range [-2.1, 0.05]
    q[:, kin.free_names.index("pelvis_ty")] += 0.93
    positions = kin.marker_positions(q)
    table = MarkerTable(time=time, names=tuple(model.marker_names), positions=positions, units="m")
    return path, model, kin, q, table


def test_exact_markers_give_exact_coordinates(leg):
    path, model, kin, q, table = leg
    result = inverse_kinematics(model, table, accuracy=1e-10)
    assert result.converged.all()
    got = result.q[:, [result.coordinate_names.index(n) for n in kin.free_names]]
    np.testing.assert_allclose(got, q, atol=1e-8)
    assert np.nanmax(result.marker_errors) < 1e-9
    assert result.free_names == kin.free_names and result.insensitive_names == ()


def test_gaps_drop_the_marker_for_that_frame(leg):
    path, model, kin, q, table = leg
    positions = table.positions.copy()
    gap = slice(10, 20)
    positions[gap, table.index("THIGH_LAT"), :] = np.nan
    positions[30, table.index("TOE"), :] = np.nan
    result = inverse_kinematics(model, MarkerTable(table.time, table.names, positions), accuracy=1e-10)
    got = result.q[:, [result.coordinate_names.index(n) for n in kin.free_names]]
    np.testing.assert_allclose(got, q, atol=1e-8)  # the other markers still determine the pose
    errors = result.marker_errors
    assert np.isnan(errors[gap, result.marker_names.index("THIGH_LAT")]).all()
    assert np.isnan(errors[30, result.marker_names.index("TOE")])
    assert np.isfinite(errors).sum() == errors.size - 11


def test_clamped_range_is_a_bound(leg):
    path, model, kin, q, table = leg
    # markers of a knee hyper-extended beyond its clamped upper bound (0.05 rad)
    q_beyond = q.copy()
    q_beyond[:, kin.free_names.index("knee_angle")] = 0.3
    positions = kin.marker_positions(q_beyond)
    result = inverse_kinematics(model, MarkerTable(table.time, table.names, positions), accuracy=1e-10)
    assert np.allclose(result.coordinate("knee_angle"), 0.05, atol=1e-12)
    assert np.nanmax(result.marker_errors) > 1e-3


def test_units_mismatch_is_detected_and_fixed(leg, tmp_path):
    path, model, kin, q, table = leg
    mm_numbers_labelled_m = MarkerTable(table.time, table.names, table.positions * 1000.0, units="m")
    write_trc(tmp_path / "wrong_units.trc", mm_numbers_labelled_m, units="m")
    with pytest.warns(UserWarning, match="look like mm"):
        result = inverse_kinematics(model, tmp_path / "wrong_units.trc", accuracy=1e-10)
    assert result.unit_factor == pytest.approx(1e-3)
    got = result.q[:, [result.coordinate_names.index(n) for n in kin.free_names]]
    np.testing.assert_allclose(got, q, atol=1e-7)


def test_weight_for_a_marker_missing_from_the_file_is_an_input_error(leg):
    path, model, kin, q, table = leg
    with pytest.raises(InputError, match="NOT_A_MARKER.*not in the marker file"):
        inverse_kinematics(model, table, weights={"NOT_A_MARKER": 1.0, "TOE": 1.0})


def test_motion_file_in_degrees_and_cli(leg, tmp_path):
    path, model, kin, q, table = leg
    trc = tmp_path / "leg.trc"
    write_trc(trc, table, units="mm")
    out = tmp_path / "leg_ik.mot"
    assert main(["ik", str(path), str(trc), "-o", str(out), "--errors", str(tmp_path / "err.sto")]) == 0
    motion = read_storage(out)
    assert motion.in_degrees
    assert list(motion.labels) == model.coordinate_names
    np.testing.assert_allclose(motion.column("knee_angle"), np.degrees(q[:, kin.free_names.index("knee_angle")]),
                               atol=1e-5)
    np.testing.assert_allclose(motion.column("pelvis_ty"), q[:, kin.free_names.index("pelvis_ty")], atol=1e-7)
    errors = read_storage(tmp_path / "err.sto")
    assert errors.labels == table.names and np.max(errors.data) < 1e-6


def test_coupled_coordinates_follow_their_couplers(shared_data):
    model = load_model(shared_data / TUTORIAL / "CompletedSettingsFiles/UF_Subject_3_Scaled.osim")
    result = inverse_kinematics(model, shared_data / TUTORIAL / "MarkerFiles/GaitTrial_markers.trc",
                                time_range=(0.0, 0.2))
    for dependent, coupler in model.coupled_coordinates.items():
        assert dependent not in result.free_names
        independent = result.coordinate(coupler.independent[0])
        expected = coupler.scale_factor * np.array([float(coupler.function(x)) for x in independent])
        np.testing.assert_allclose(result.coordinate(dependent), expected, atol=1e-12)
    for name in result.locked_names:
        assert np.all(result.coordinate(name) == model.coordinate(name).default_value)


def test_tutorial_ik_settings_are_read(shared_data):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # marker file found relative to the step folder
        settings = read_ik_settings(shared_data / TUTORIAL / "IKSettingsFiles/IKSettingsGait.xml")
    assert len(settings.marker_weights) == 32 and "Lumbar" not in settings.marker_weights
    assert settings.time_range == (0.0, 1.07)
    assert settings.marker_file == (shared_data / TUTORIAL / "MarkerFiles/GaitTrial_markers.trc").resolve()
    assert settings.output_motion_file is None


def test_against_opensim_on_gait_trial(shared_data, bridge):
    """Both solvers converged tightly (accuracy 1e-8): the same local minimum."""
    folder = shared_data / TUTORIAL
    model_file = folder / "CompletedSettingsFiles/UF_Subject_3_Scaled.osim"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings = read_ik_settings(folder / "IKSettingsFiles/IKSettingsGait.xml")
    ours = inverse_kinematics(model_file, settings.marker_file, weights=settings.marker_weights,
                              time_range=settings.time_range, accuracy=1e-8)
    theirs = bridge.call("opensim_inverse_kinematics", model=str(model_file), marker_file=str(settings.marker_file),
                         marker_weights=settings.marker_weights, time_range=settings.time_range, accuracy=1e-8)
    assert list(theirs["coordinates"]) == list(ours.coordinate_names)
    np.testing.assert_allclose(theirs["time"], ours.time)
    excluded = set(ours.locked_names) | set(ours.insensitive_names)
    assert excluded == {"knee_adduction_r", "mtp_angle_r", "knee_adduction_l", "mtp_angle_l", "pro_sup_r",
                        "wrist_flex_r", "wrist_dev_r", "pro_sup_l", "wrist_flex_l", "wrist_dev_l"}
    rotational = {c.name for c in load_model(model_file).coordinates if c.motion_type == "rotational"}
    for k, name in enumerate(ours.coordinate_names):
        if name not in ours.free_names:
            continue
        rms = float(np.sqrt(np.mean((ours.q[:, k] - theirs["q"][:, k]) ** 2)))
        if name in rotational:
            assert np.degrees(rms) <= 0.1, name
        else:
            assert rms <= 1e-4, name
    their_rms = float(np.sqrt(np.nanmean(theirs["errors"] ** 2)))
    assert abs(ours.marker_rms() - their_rms) <= 0.01 * their_rms


def test_leg_model_loads_in_opensim_with_the_same_kinematics(leg, bridge):
    """OpenSim reads the generated leg model as nmsm does: same names, and our IK solution
    puts OpenSim's markers on the experimental ones."""
    path, model, kin, q, table = leg
    result = inverse_kinematics(model, table, accuracy=1e-10)
    info = bridge.call("model_info", path=str(path))
    assert info["coordinates"] == model.coordinate_names
    assert info["markers"] == model.marker_names
    theirs = bridge.call("oracle_kinematics", path=str(path), q=result.q)
    np.testing.assert_allclose(theirs["markers"], table.positions, atol=1e-8)


def test_ik_settings_file_with_weights_and_a_coordinate_task(leg, tmp_path):
    path, model, kin, q, table = leg
    trc = tmp_path / "leg.trc"
    write_trc(trc, table, units="m")
    settings = tmp_path / "ik.xml"
    settings.write_text("""<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
  <InverseKinematicsTool>
    <accuracy>1e-10</accuracy>
    <IKTaskSet><objects>
      <IKMarkerTask name="TOE"><apply>false</apply><weight>1</weight></IKMarkerTask>
      <IKMarkerTask name="HEEL"><apply>true</apply><weight>5</weight></IKMarkerTask>
      <IKCoordinateTask name="knee_angle"><apply>true</apply><weight>1e6</weight>
        <value_type>manual_value</value_type><value>-0.5</value></IKCoordinateTask>
    </objects></IKTaskSet>
    <marker_file>leg.trc</marker_file>
    <time_range>0.2 0.4</time_range>
    <output_motion_file>out/leg_ik.mot</output_motion_file>
  </InverseKinematicsTool>
</OpenSimDocument>
""")
    (tmp_path / "out").mkdir()
    result = run_ik_files(path, ik_settings=settings)
    assert result.time[0] == pytest.approx(0.2) and result.time[-1] == pytest.approx(0.4)
    assert result.marker_names == ("HEEL",)  # only the applied marker task
    np.testing.assert_allclose(result.coordinate("knee_angle"), -0.5, atol=1e-4)  # held by the coordinate task
    assert (tmp_path / "out" / "leg_ik.mot").is_file()


def test_first_frame_leaves_a_default_on_a_range_bound(shared_data, bridge):
    """The tutorial's hips trial starts with the arms bent while the model's default elbows
    sit on their lower bound (0 in [0, 150 deg]): started there only, the first frame ended
    with straight elbows and rotated arms (48.8 mm RMS over the trial) and every later frame
    stayed in that minimum. With the mid-range start as well, nmsm lands where OpenSim does."""
    folder = shared_data / TUTORIAL
    model_file = folder / "CompletedSettingsFiles/UF_Subject_3_Scaled.osim"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings = read_ik_settings(folder / "IKSettingsFiles/IKSettingsHips.xml")
    window = (settings.time_range[0], settings.time_range[0] + 0.5)
    ours = inverse_kinematics(model_file, settings.marker_file, weights=settings.marker_weights, time_range=window,
                              accuracy=1e-8)
    theirs = bridge.call("opensim_inverse_kinematics", model=str(model_file), marker_file=str(settings.marker_file),
                         marker_weights=settings.marker_weights, time_range=window, accuracy=1e-8)
    their_rms = float(np.sqrt(np.nanmean(theirs["errors"] ** 2)))
    assert abs(ours.marker_rms() - their_rms) <= 0.01 * their_rms
    for name in ("elbow_flex_r", "elbow_flex_l"):
        k = list(ours.coordinate_names).index(name)
        assert np.degrees(np.abs(ours.q[:, k] - theirs["q"][:, k]).max()) <= 1.0, name
        assert np.degrees(ours.q[0, k]) > 90.0, name  # bent, as the markers show


def test_first_frame_starts_move_only_coordinates_on_a_bound():
    from nmsm.tools.jmp.ik import first_frame_starts

    lower = np.array([0.0, -1.0, -np.inf, -2.0])
    upper = np.array([2.0, 1.0, np.inf, 0.0])
    inside = np.array([1.0, 0.5, 3.0, -1.0])
    assert len(first_frame_starts(inside, lower, upper)) == 1
    default, moved = first_frame_starts(np.array([0.0, 0.5, 3.0, 0.0]), lower, upper)
    np.testing.assert_array_equal(default, [0.0, 0.5, 3.0, 0.0])
    np.testing.assert_array_equal(moved, [1.0, 0.5, 3.0, -1.0])

"""Muscle Analysis equivalent against OpenSim's MuscleAnalysis and the shared MAData layout."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from nmsm.errors import ModelError
from nmsm.io.storage import Table, read_storage
from nmsm.model import load_model
from nmsm.model.muscle_analysis import analyze_motion, coordinate_speeds, motion_poses
from nmsm.model.surrogate import fit_surrogate_model
from nmsm.model.surrogate_data import read_samples

KICK = "treatment/surrogate_kick_tutorial"
SURROGATE_COORDINATES = ["hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r",
                         "subtalar_angle_r"]
FILE_ROUNDING = 5e-9  # OpenSim's MuscleAnalysis writes 8 decimals


@pytest.fixture(scope="module")
def opensim_ma(shared_data, bridge, tmp_path_factory):
    """OpenSim's MuscleAnalysis of the kick motion (all muscles, the six surrogate coordinates + pelvis_tilt)."""
    out = tmp_path_factory.mktemp("osim_ma")
    bridge.call("run_muscle_analysis", model=str(shared_data / KICK / "RightLegAndPelvis.osim"),
                coordinates_file=str(shared_data / KICK / "preprocessed/IKData/drive_kick1.sto"),
                results_directory=str(out), name="kick",
                moment_arm_coordinates=SURROGATE_COORDINATES + ["pelvis_tilt", "knee_angle_r_beta"])
    return out


@pytest.fixture(scope="module")
def ours(shared_data, bridge):
    return analyze_motion(shared_data / KICK / "RightLegAndPelvis.osim",
                          shared_data / KICK / "preprocessed/IKData/drive_kick1.sto",
                          coordinates=SURROGATE_COORDINATES + ["pelvis_tilt", "knee_angle_r_beta"], bridge=bridge)


def test_lengths_and_moment_arms_match_opensim_muscle_analysis(ours, opensim_ma) -> None:
    length = read_storage(opensim_ma / "kick_MuscleAnalysis_Length.sto")
    assert length.labels == ours.muscles
    np.testing.assert_allclose(length.time, ours.time, atol=1e-8)
    assert np.abs(length.data - ours.lengths).max() <= FILE_ROUNDING + 1e-12
    assert ours.sources == {"bflh_r": "path", "soleus_r": "path", "tibant_r": "path", "bfsh_r": "opensim",
                            "gasmed_r": "opensim", "glmax2_r": "opensim", "iliacus_r": "opensim",
                            "recfem_r": "opensim", "vasmed_r": "opensim"}
    for k, coord in enumerate(ours.coordinates):
        arms = read_storage(opensim_ma / f"kick_MuscleAnalysis_MomentArm_{coord}.sto")
        # exact paths: -dL/dq; wrapping and patella muscles: OpenSim's computeMomentArm through the bridge
        assert np.abs(arms.data - ours.moment_arms[:, :, k]).max() <= FILE_ROUNDING + 1e-12, coord


def test_dependent_coordinate_reports_its_independent_moment_arm(ours, opensim_ma) -> None:
    beta = ours.coordinates.index("knee_angle_r_beta")
    knee = ours.coordinates.index("knee_angle_r")
    assert np.array_equal(ours.moment_arms[:, :, beta], ours.moment_arms[:, :, knee])
    osim_beta = read_storage(opensim_ma / "kick_MuscleAnalysis_MomentArm_knee_angle_r_beta.sto")
    osim_knee = read_storage(opensim_ma / "kick_MuscleAnalysis_MomentArm_knee_angle_r.sto")
    np.testing.assert_array_equal(osim_beta.data, osim_knee.data)  # what OpenSim writes there


def test_coordinate_speeds_equal_opensim_gcv_spline(shared_data, bridge) -> None:
    motion = shared_data / KICK / "preprocessed/IKData/drive_kick1.sto"
    table = read_storage(motion)
    columns = ["hip_flexion_r", "knee_angle_r", "ankle_angle_r", "pelvis_tx"]
    ref = bridge.call("gcv_spline_derivatives", motion=str(motion), columns=columns)
    ours = coordinate_speeds(table.time, table.columns(columns))
    assert np.abs(ours - ref["derivatives"]).max() <= 1e-9 * max(1.0, np.abs(ref["derivatives"]).max())


def test_velocity_is_the_time_derivative_of_opensim_lengths(shared_data, bridge, ours) -> None:
    """V = dL/dq q̇ equals d/dt of OpenSim lengths along the same coordinate spline."""
    path = shared_data / KICK / "RightLegAndPelvis.osim"
    model = load_model(path)
    table = read_storage(shared_data / KICK / "preprocessed/IKData/drive_kick1.sto")
    q = motion_poses(model, table)
    dependents = set(model.coupled_coordinates)
    cols = [i for i, n in enumerate(model.coordinate_names) if n not in dependents]
    zero = np.zeros(len(cols))
    natural = ([(3, zero), (4, zero)], [(3, zero), (4, zero)])
    spline = make_interp_spline(table.time, q[:, cols], k=5, bc_type=natural)
    frames = np.arange(2, table.n_rows - 2, 5)
    h = 1e-5
    sides = []
    for sign in (1.0, -1.0):
        full = q[frames].copy()
        full[:, cols] = spline(table.time[frames] + sign * h)
        sides.append(bridge.call("muscle_lengths", model=str(path), q=full, coordinates=model.coordinate_names,
                                 muscles=list(ours.muscles)))
    fd = (sides[0] - sides[1]) / (2 * h)
    assert np.abs(fd - ours.velocities[frames]).max() <= 1e-6


def test_written_files_follow_the_muscle_analysis_layout(ours, shared_data, tmp_path) -> None:
    paths = ours.write(tmp_path / "MAData", "drive_kick1")
    folder = tmp_path / "MAData" / "drive_kick1"
    assert {p.name for p in paths} == {"drive_kick1_Length.sto", "drive_kick1_Velocity.sto"} | {
        f"drive_kick1_MomentArm_{c}.sto" for c in ours.coordinates}
    shared = read_storage(shared_data / "mtp/uf_subject3_tutorial/passive_moment_data/MAData/Thelen_AnklePassive_03/"
                                        "Thelen_AnklePassive_03_MuscleAnalysis_MomentArm_knee_angle_r.sto")
    mine = read_storage(folder / "drive_kick1_MomentArm_knee_angle_r.sto")
    assert mine.name == shared.name == "MomentArm_knee_angle_r"
    assert mine.labels == shared.labels  # the same nine muscles, same order
    assert mine.metadata["version"] == shared.metadata["version"] == "1"
    assert mine.metadata["inDegrees"] == shared.metadata["inDegrees"] == "no"
    assert [c for c in mine.comments if c] == [c for c in shared.comments if c]
    assert mine.n_rows == len(ours.time) and int(mine.metadata["nRows"]) == mine.n_rows
    np.testing.assert_array_equal(read_storage(folder / "drive_kick1_Length.sto").data, ours.lengths)


def test_surrogate_engine_and_missing_surrogate(shared_data, bridge) -> None:
    path = shared_data / KICK / "RightLegAndPelvis.osim"
    motion = shared_data / KICK / "preprocessed/IKData/drive_kick1.sto"
    with pytest.raises(ModelError, match="gasmed_r"):
        analyze_motion(path, motion, engine="nmsm", bridge=bridge)
    model = load_model(path)
    rotational = {c.name for c in model.coordinates if c.is_rotational}
    samples = read_samples(shared_data / KICK / "surrogateData", SURROGATE_COORDINATES, rotational)
    surrogate = fit_surrogate_model(samples, 5, 1e-4, holdout_fraction=0.0)
    result = analyze_motion(path, motion, engine="nmsm", surrogate=surrogate, coordinates=SURROGATE_COORDINATES,
                            model=model)
    assert result.sources["gasmed_r"] == "surrogate" and result.sources["soleus_r"] == "path"
    reference = analyze_motion(path, motion, engine="opensim", coordinates=SURROGATE_COORDINATES, model=model,
                               bridge=bridge)
    i = result.muscles.index("soleus_r")
    assert np.abs(result.lengths[:, i] - reference.lengths[:, i]).max() <= 1e-9
    j = result.muscles.index("iliacus_r")
    assert np.sqrt(np.mean((result.lengths[:, j] - reference.lengths[:, j]) ** 2)) <= 1e-3


def test_lowpass_filtering_matches_opensim(shared_data, bridge, tmp_path) -> None:
    model_file = shared_data / KICK / "RightLegAndPelvis.osim"
    motion = shared_data / KICK / "preprocessed/IKData/drive_kick1.sto"
    bridge.call("run_muscle_analysis", model=str(model_file), coordinates_file=str(motion),
                results_directory=str(tmp_path), name="f6", moment_arm_coordinates=["knee_angle_r"],
                lowpass_cutoff_frequency=6.0)
    ours = analyze_motion(model_file, motion, muscles=["bflh_r", "soleus_r", "tibant_r"], coordinates=["knee_angle_r"],
                          lowpass_hz=6.0)
    unfiltered = analyze_motion(model_file, motion, muscles=["bflh_r", "soleus_r", "tibant_r"],
                                coordinates=["knee_angle_r"])
    ref = read_storage(tmp_path / "f6_MuscleAnalysis_Length.sto").select(list(ours.muscles))
    error = np.abs(ref.data - ours.lengths).max(axis=1)
    # measured: <= 1e-8 m at 49 of 55 frames (median 4e-9, the file's rounding), 1.1e-8 .. 1.4e-7 m at six
    # isolated frames (cause not identified; without filtering every frame agrees to the file's rounding)
    assert np.median(error) <= FILE_ROUNDING and error.max() <= 2e-7
    assert np.abs(ref.data - unfiltered.lengths).max() > 1e-4  # the filter matters for this motion


RAJAGOPAL = "jmp/rajagopal_isolated_knee/Rajagopal_4.0_RCNL_markers_scaled.osim"
GAIT = "preprocessing/uf_subject3_tutorial/PreCompleted/input_data/GaitTrial_IKResults.mot"
#: gastrocnemii over two wrap cylinders (condyles and shank), and path-point muscles on the left
#: foot, whose subtalar angle leaves its clamped range in this motion
WRAP_MUSCLES = ["gasmed_r", "gaslat_r", "gasmed_l", "gaslat_l", "soleus_l", "perlong_l"]
WRAP_COORDINATES = ["knee_angle_r", "ankle_angle_r", "knee_angle_l", "ankle_angle_l", "subtalar_angle_l"]


def test_wrapping_gastrocnemii_match_opensim_muscle_analysis(shared_data, bridge, tmp_path) -> None:
    """Gait frames 0.10-0.30 s on the Rajagopal model: the condyle wrap of each gastrocnemius
    engages or lets go in this window (frames 0.10, 0.16 and 0.25 s on the right; 0.04 and
    0.10 s on the left), and the motion's locked knee_adduction (6.0 deg, default 6.5) and
    out-of-range subtalar_angle_l are set as OpenSim's AnalyzeTool sets them."""
    model, motion = shared_data / RAJAGOPAL, shared_data / GAIT
    bridge.call("run_muscle_analysis", model=str(model), coordinates_file=str(motion),
                results_directory=str(tmp_path), name="gait", muscles=WRAP_MUSCLES,
                moment_arm_coordinates=WRAP_COORDINATES, start_time=0.10, end_time=0.30)
    table = read_storage(motion)
    window = (table.time >= 0.10 - 1e-9) & (table.time <= 0.30 + 1e-9)
    cropped = Table(time=table.time[window], labels=table.labels, data=table.data[window],
                    in_degrees=table.in_degrees, source=table.source)
    with pytest.warns(UserWarning, match="clamped coordinate.*subtalar_angle_l"):
        ours = analyze_motion(model, cropped, muscles=WRAP_MUSCLES, coordinates=WRAP_COORDINATES, bridge=bridge)
    assert ours.sources["gasmed_r"] == "opensim" and ours.sources["perlong_l"] == "path"
    lengths = read_storage(tmp_path / "gait_MuscleAnalysis_Length.sto")
    np.testing.assert_allclose(lengths.time, ours.time, atol=1e-8)
    assert np.abs(lengths.data - ours.lengths).max() <= 1e-6
    for k, coord in enumerate(WRAP_COORDINATES):
        arms = read_storage(tmp_path / f"gait_MuscleAnalysis_MomentArm_{coord}.sto")
        assert np.abs(arms.data - ours.moment_arms[:, :, k]).max() <= 1e-5, coord

"""Trial files by prefix: exact name first, unique substring else, ambiguity is an error."""

from __future__ import annotations

from pathlib import Path

import pytest

from nmsm.errors import InputError
from nmsm.io.trials import find_file_by_suffix, find_trial_file, find_trial_folder, trial_prefixes


@pytest.fixture
def data(tmp_path: Path) -> Path:
    ik = tmp_path / "IKData"
    ik.mkdir()
    for name in ("gait_1.sto", "gait_10.sto", "S01_squat_2.mot", "notes.txt"):
        (ik / name).write_text("x")
    ma = tmp_path / "MAData"
    for name in ("gait_1", "gait_10"):
        (ma / name).mkdir(parents=True)
        (ma / name / f"{name}_MuscleAnalysis_Length.sto").write_text("x")
        (ma / name / f"{name}_MuscleAnalysis_MomentArm_knee_angle_r.sto").write_text("x")
        (ma / name / f"{name}_MuscleAnalysis_MomentArm_knee_angle_r_beta.sto").write_text("x")
    return tmp_path


def test_prefixes_are_table_names_without_extension(data: Path) -> None:
    assert trial_prefixes(data / "IKData") == ["S01_squat_2", "gait_1", "gait_10"]


def test_exact_name_wins_over_substring(data: Path) -> None:
    """The original's substring match takes gait_10 for gait_1; an exact stem wins here."""
    assert find_trial_file(data / "IKData", "gait_1").name == "gait_1.sto"
    assert find_trial_folder(data / "MAData", "gait_1").name == "gait_1"


def test_unique_substring_is_accepted(data: Path) -> None:
    assert find_trial_file(data / "IKData", "squat_2").name == "S01_squat_2.mot"


def test_ambiguous_substring_lists_the_candidates(data: Path) -> None:
    with pytest.raises(InputError) as info:
        find_trial_file(data / "IKData", "gait")
    assert "gait_1.sto" in info.value.detail and "gait_10.sto" in info.value.detail


def test_missing_trial_and_folder(data: Path) -> None:
    with pytest.raises(InputError, match="no file for trial 'run_3'"):
        find_trial_file(data / "IKData", "run_3")
    with pytest.raises(InputError, match="folder not found"):
        find_trial_file(data / "IDData", "gait_1")


def test_file_by_suffix(data: Path) -> None:
    folder = data / "MAData" / "gait_1"
    assert find_file_by_suffix(folder, "_Length").name == "gait_1_MuscleAnalysis_Length.sto"
    found = find_file_by_suffix(folder, "_MomentArm_knee_angle_r")
    assert found.name == "gait_1_MuscleAnalysis_MomentArm_knee_angle_r.sto"
    with pytest.raises(InputError, match="no file ending"):
        find_file_by_suffix(folder, "_Velocity")


def test_prefix_never_runs_into_another_digit(tmp_path: Path) -> None:
    """mtp19: without gait_1.sto, trial gait_1 must not take gait_10.sto (nor 1_gait take 11_gait.sto)."""
    ik = tmp_path / "IKData"
    ik.mkdir()
    for name in ("gait_10.sto", "11_gait.sto"):
        (ik / name).write_text("x")
    with pytest.raises(InputError) as info:
        find_trial_file(ik, "gait_1")
    assert "no file for trial 'gait_1' (found: 11_gait.sto, gait_10.sto)" in info.value.detail
    with pytest.raises(InputError, match="no file for trial '1_gait'"):
        find_trial_file(ik, "1_gait")
    ma = tmp_path / "MAData"
    (ma / "gait_10").mkdir(parents=True)
    with pytest.raises(InputError, match=r"no folder for trial 'gait_1' \(found: gait_10\)"):
        find_trial_folder(ma, "gait_1")


def test_prefix_with_a_suffix_still_matches(tmp_path: Path) -> None:
    """Real layouts name files <trial>_<what> (mtpResults/gait_1_muscleActivations.sto)."""
    folder = tmp_path / "muscleActivations"
    folder.mkdir()
    for name in ("gait_1_muscleActivations.sto", "gait_10_muscleActivations.sto", "speed1_gait_2_ID.mot"):
        (folder / name).write_text("x")
    assert find_trial_file(folder, "gait_1").name == "gait_1_muscleActivations.sto"
    assert find_trial_file(folder, "gait_2").name == "speed1_gait_2_ID.mot"
    assert find_trial_file(folder, "gait_10").name == "gait_10_muscleActivations.sto"

"""Bad NCP input gives InputError naming the file, the element or column, and what was expected."""

from __future__ import annotations

import pytest
from lxml import etree

from nmsm.errors import InputError
from nmsm.examples.synthetic_ncp import make_synthetic_ncp_case
from nmsm.io.storage import read_storage, table_from_columns, write_storage
from nmsm.tools.ncp.run import run_settings


@pytest.fixture
def case(tmp_path):
    return make_synthetic_ncp_case(tmp_path, n_trials=2, n_points=41)


def _edit(case, change) -> None:
    tree = etree.parse(str(case.settings_file))
    change(tree.getroot().find("NeuralControlPersonalizationTool"))
    tree.write(str(case.settings_file))


def test_synergy_group_not_in_model(case) -> None:
    _edit(case, lambda tool: tool.find("RCNLSynergySet/RCNLSynergy/muscle_group_name").__setattr__("text", "RightLegs"))
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, print_level=0)
    message = str(info.value)
    assert str(case.settings_file) in message and "'RightLegs' is not a ForceSet group" in message
    assert "close matches: RightLeg" in message and "<muscle_group_name>" in message


def test_more_synergies_than_muscles(case) -> None:
    _edit(case, lambda tool: tool.find("RCNLSynergySet/RCNLSynergy/num_synergies").__setattr__("text", "9"))
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, print_level=0, enforce_bilateral_symmetry=False)
    message = str(info.value)
    assert "asks for 9 synergies but has 8 muscle(s)" in message and "<num_synergies>" in message
    assert "at most 8 synergies" in message


def test_mtp_activations_lacking_a_muscle_of_the_group(case) -> None:
    path = case.folder / "mtp" / "muscleActivations" / "trial_2_muscleActivations.sto"
    table = read_storage(path)
    kept = [label for label in table.labels if label != "vasti_l"]
    write_storage(path, table_from_columns(table.time, {k: table.column(k) for k in kept}))
    with pytest.raises(InputError) as info:
        run_settings(case.settings_file, print_level=0)
    message = str(info.value)
    assert str(path) in message and "column 'vasti_l'" in message and "lack muscle(s) vasti_l" in message


def test_muscle_without_mtp_activations_in_every_trial_is_named(case) -> None:
    """A muscle missing from every trial's MTP activations is not an error (the moments drive
    it, tools.md §5), but the run log names it."""
    for path in (case.folder / "mtp" / "muscleActivations").glob("*.sto"):
        table = read_storage(path)
        write_storage(path, table_from_columns(table.time, {k: table.column(k) for k in table.labels
                                                            if k != "vasti_l"}))
    outcome = run_settings(case.settings_file, print_level=0)
    log = (outcome.results_directory / "commandWindowOutput.txt").read_text()
    prefix = "muscles without MTP activations (driven by the moments only): "
    line = next(text for text in log.splitlines() if text.startswith(prefix))
    named = line[len(prefix):].split(", ")
    assert "vasti_l" in named and "vasti_r" not in named, line


def test_mtp_activations_with_other_frame_count(case) -> None:
    path = case.folder / "mtp" / "muscleActivations" / "trial_1_muscleActivations.sto"
    table = read_storage(path)
    write_storage(path, table_from_columns(table.time[:-1], {k: table.column(k)[:-1] for k in table.labels}))
    with pytest.raises(InputError, match="have 40 rows but its ID/MA data have 41"):
        run_settings(case.settings_file, print_level=0)


def test_crossing_muscle_in_no_synergy_group(case) -> None:
    def drop_left(tool):
        synergies = tool.find("RCNLSynergySet")
        synergies.remove(synergies.findall("RCNLSynergy")[1])
        tool.find("enforce_bilateral_symmetry").text = "false"
    _edit(case, drop_left)
    with pytest.raises(InputError, match=r"glmax_l.* cross the coordinates of <coordinate_list> but are in no synergy group"):
        run_settings(case.settings_file, print_level=0)


def test_symmetry_needs_two_groups(case) -> None:
    _edit(case, lambda tool: tool.find("RCNLSynergySet").remove(tool.find("RCNLSynergySet").findall("RCNLSynergy")[1]))
    with pytest.raises(InputError, match="bilateral symmetry needs exactly two synergy groups"):
        run_settings(case.settings_file, print_level=0)


def test_missing_moment_arm_file(case) -> None:
    (case.folder / "data" / "MAData" / "trial_1" / "trial_1_MomentArm_knee_angle_l.sto").unlink()
    with pytest.raises(InputError, match="moment-arm file missing for coordinate 'knee_angle_l'"):
        run_settings(case.settings_file, print_level=0)


def test_renamed_inverse_dynamics_file_is_named_as_the_trial_s_origin(case) -> None:
    """A renamed IDData file becomes a trial the other folders lack: the error says where the trial came from."""
    ident = case.folder / "data" / "IDData"
    (ident / "trial_2.sto").rename(ident / "trial_7.sto")
    with pytest.raises(InputError, match=r"no folder for trial 'trial_7' .*; trial 'trial_7' is a file name of "
                                         r".*IDData \(the trials are those files unless <trial_prefixes> lists them\)"):
        run_settings(case.settings_file, print_level=0)


def test_results_next_to_the_settings_keep_the_settings_file(case) -> None:
    before = case.settings_file.read_bytes()
    run = run_settings(case.settings_file, results_directory=case.folder, print_level=0)
    assert run.results_directory == case.folder and (case.folder / "synergyWeights.sto").is_file()
    assert case.settings_file.read_bytes() == before


def test_read_only_results_folder_is_refused_before_optimizing(case, tmp_path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        with pytest.raises(InputError, match="<results_directory>: results folder .* cannot be written"):
            run_settings(case.settings_file, results_directory=locked / "out", print_level=0)
        assert not any(locked.iterdir())
    finally:
        locked.chmod(0o755)

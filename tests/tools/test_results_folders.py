"""Results folders of the personalization tools (nmsm.core.results): refused input folders,
refusals before solving, and reruns that never mix with an earlier run's files."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

from nmsm.errors import InputError


def _writable_copy(source: Path, target: Path) -> Path:
    shutil.copytree(source, target)
    for path in [target, *target.rglob("*")]:
        path.chmod(path.stat().st_mode | 0o200)
    return target


@pytest.fixture
def mtp_tutorial(shared_data: Path, tmp_path: Path) -> Path:
    return _writable_copy(shared_data / "mtp" / "uf_subject3_tutorial", tmp_path / "mtp")


def _tree(folder: Path) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_mtp_rerun_without_synx_moves_the_synx_files_of_the_earlier_run_aside(mtp_tutorial: Path) -> None:
    from nmsm.tools.mtp.run import run_settings

    settings = mtp_tutorial / "CompletedSettingsFiles"
    out = mtp_tutorial / "results"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(settings / "MTPSettingsV1.xml", results_directory=out)
    assert (out / "Analysis" / "muscleActivationsSynx").is_dir()
    with pytest.warns(UserWarning, match="files of the earlier mtp run there were moved to"):
        run_settings(settings / "MTPSettingsV3.xml", results_directory=out)
    assert not (out / "Analysis" / "muscleActivationsSynx").exists()  # V3 has no SynX
    assert not (out / "MTPSettingsV1.xml").exists()
    assert (out / "superseded" / "Analysis" / "muscleActivationsSynx").is_dir()
    assert (out / "MTPSettingsV3.xml").is_file() and (out / "Analysis" / "muscleActivations").is_dir()


def test_mtp_results_in_a_data_folder_are_refused_before_solving(mtp_tutorial: Path, monkeypatch) -> None:
    from nmsm.tools.mtp import run as mtp_run

    monkeypatch.setattr(mtp_run, "initialize_lengths", lambda *a, **k: pytest.fail("solved before refusing"))
    data = mtp_tutorial / "preprocessed"
    before = _tree(data)
    for target, where in [(data, "is the <data_directory> folder"), (data / "IDData", "is the <data_directory> IDData"),
                          (data / "MAData" / "x", "is inside the <data_directory> MAData")]:
        with pytest.raises(InputError, match=where) as info:
            mtp_run.run_settings(mtp_tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml", results_directory=target)
        assert "<results_directory>" in str(info.value) and "MTPSettingsV3.xml" in str(info.value)
    assert _tree(data) == before


def test_mtp_results_next_to_the_settings_keep_the_settings(mtp_tutorial: Path) -> None:
    from nmsm.tools.mtp.run import run_settings

    settings = mtp_tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml"
    text = settings.read_bytes()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run_settings(settings, results_directory=settings.parent)
    assert settings.read_bytes() == text
    assert (settings.parent / "UF_Subject_3_reduced_muscles_mtp.osimx").is_file()


def test_mtp_rerun_over_the_original_results_sets_them_aside(mtp_tutorial: Path) -> None:
    from nmsm.tools.mtp.run import run_settings

    results = mtp_tutorial / "CompletedSettingsFiles" / "MTPResultsV3"
    original = (results / "UF_Subject_3_reduced_muscles_mtp.osimx").read_bytes()
    with pytest.warns(UserWarning, match="were not written by it; moved to"):
        run_settings(mtp_tutorial / "CompletedSettingsFiles" / "MTPSettingsV3.xml")
    assert (results / "superseded" / "replaced" / "UF_Subject_3_reduced_muscles_mtp.osimx").read_bytes() == original
    assert (results / "UF_Subject_3_reduced_muscles_mtp.osimx").read_bytes() != original


def test_gcp_results_in_its_input_folder_are_refused_and_leave_nothing(shared_data: Path, tmp_path: Path,
                                                                        monkeypatch) -> None:
    from nmsm.tools.gcp import run as gcp_run

    tutorial = _writable_copy(shared_data / "gcp" / "uf_subject3_tutorial", tmp_path / "gcp")
    monkeypatch.setattr(gcp_run, "load_feet", lambda *a, **k: pytest.fail("worked before refusing"))
    data = tutorial / "preprocessed"
    before = _tree(data)
    settings = tutorial / "CompletedSettingsFiles" / "GCPSettingsV1.xml"
    for target, where in [(data, "is the <input_directory> folder"), (data / "IKData", "is the motion"),
                          (data / "GRFData" / "new", "is inside the ground reactions")]:
        with pytest.raises(InputError, match=where):
            gcp_run.run_settings(settings, results_directory=target)
    assert _tree(data) == before and not (data / "GRFData" / "new").exists()


def test_gcp_failure_leaves_no_empty_results_folder(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.tools.gcp.run import run_settings

    tutorial = _writable_copy(shared_data / "gcp" / "uf_subject3_tutorial", tmp_path / "gcp")
    settings = tutorial / "CompletedSettingsFiles" / "GCPSettingsV1.xml"
    settings.write_text(settings.read_text().replace("IKData/gait_1.sto", "IKData/missing.sto"))
    with pytest.raises(InputError):
        run_settings(settings, results_directory=tmp_path / "out" / "gcp")
    assert not (tmp_path / "out").exists()


def test_ncp_results_in_the_mtp_results_folder_are_refused(shared_data: Path, tmp_path: Path, monkeypatch) -> None:
    from nmsm.tools.ncp import run as ncp_run

    tutorial = _writable_copy(shared_data / "ncp" / "uf_subject3_tutorial", tmp_path / "ncp")
    monkeypatch.setattr(ncp_run, "solve", lambda *a, **k: pytest.fail("solved before refusing"))
    before = _tree(tutorial / "mtpResults")
    with pytest.raises(InputError, match="is the <mtp_results_directory> folder"):
        ncp_run.run_settings(tutorial / "CompletedSettingsFiles" / "NCPSettingsV1.xml",
                             results_directory=tutorial / "mtpResults")
    assert _tree(tutorial / "mtpResults") == before


def test_jmp_output_model_onto_the_input_is_refused_before_solving(shared_data: Path, tmp_path: Path,
                                                                   monkeypatch) -> None:
    from lxml import etree

    from nmsm.tools.jmp import run as jmp_run

    tutorial = _writable_copy(shared_data / "jmp" / "uf_subject3_tutorial", tmp_path / "jmp")
    settings = next(tutorial.rglob("JMPSettingsSimultaneous.xml"))
    tree = etree.parse(str(settings))
    tool = tree.getroot().find("JointModelPersonalizationTool")
    model = jmp_run.read_settings(settings).input_model_file
    tool.find("output_model_file").text = Path(model).name
    results = tool.find("results_directory")
    if results is None:
        results = etree.SubElement(tool, "results_directory")
    results.text = str(Path(model).parent)
    tree.write(str(settings))
    monkeypatch.setattr(jmp_run, "run_task", lambda *a, **k: pytest.fail("solved before refusing"))
    before = Path(model).read_bytes()
    with pytest.raises(InputError, match="would overwrite an input file") as info:
        jmp_run.run_settings(settings, quiet=True)
    assert "<output_model_file>" in str(info.value)
    assert Path(model).read_bytes() == before


def test_treatment_run_over_the_original_results_sets_them_aside(shared_data: Path, tmp_path: Path) -> None:
    """Torque TO V1 run as the tutorial gives it writes into the tutorial's own
    ``TorqueTOResultsV1``: the original's files it replaces are moved to
    ``superseded/replaced`` with a warning (were overwritten silently), and a second run
    retires the first run's files, not the original's."""
    from nmsm.tools.treatment.run import run_settings

    tutorial = _writable_copy(shared_data / "treatment" / "torque_kick_tutorial", tmp_path / "kick")
    results = tutorial / "CompletedSettingsFiles" / "TorqueTOResultsV1"
    original = _tree(results)
    with pytest.warns(UserWarning, match="were not written by it; moved to"):
        run_settings(tutorial / "CompletedSettingsFiles" / "TorqueTOSettingsV1.xml", print_level=0)
    aside = results / "superseded" / "replaced"
    assert {name: data for name, data in _tree(aside).items()} == original  # every original file, unchanged
    first = (results / "drive_kick1_states.sto").read_bytes()
    with pytest.warns(UserWarning, match="files of the earlier drive_kick1 run there were moved to"):
        run_settings(tutorial / "CompletedSettingsFiles" / "TorqueTOSettingsV1.xml", print_level=0)
    assert _tree(aside) == original
    assert (results / "superseded" / "drive_kick1_states.sto").read_bytes() == first

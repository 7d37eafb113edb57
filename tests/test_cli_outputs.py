"""Output paths of ``id``, ``markers``, ``ik``, ``surrogate``, ``muscle-analysis``, ``vaf``,
``report``, ``export`` and ``plot`` (nmsm/io/output_file.py, docs/architecture.md "Output
paths"): an input is never overwritten, every output is checked before anything is computed
(a missing folder, a folder for a file, a file for a folder: one ``nmsm: error:`` line), a
failure leaves no partial output, single files are written atomically, the several files of
``muscle-analysis``, ``plot`` and ``surrogate --write-samples`` all or nothing, and
``report`` leaves the tree it reports on untouched."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.examples.synthetic_jmp import leg_model_xml
from nmsm.io.osimx import OsimxModel, write_osimx
from nmsm.io.storage import table_from_columns, write_storage
from nmsm.io.trc import MarkerTable, write_trc
from nmsm.model import load_model
from nmsm.tools.jmp.marker_model import MarkerKinematics

KICK = Path("treatment") / "surrogate_kick_tutorial"


@pytest.fixture(scope="module")
def source(tmp_path_factory) -> Path:
    """A folder of small inputs: the built-in leg (model, motion, markers), activations, a
    report tree, a personalized .osimx, a JMP results folder whose figures fail, a treatment
    results folder without figures (``treat``: two are drawn)."""
    folder = tmp_path_factory.mktemp("inputs")
    (folder / "leg.osim").write_bytes(leg_model_xml())
    model = load_model(folder / "leg.osim")
    time = np.linspace(0.0, 0.4, 11)
    columns = {c.name: c.default_value + 0.1 * np.sin(5 * time + k) for k, c in enumerate(model.coordinates)}
    columns["pelvis_ty"] = columns["pelvis_ty"] + 0.93
    write_storage(folder / "leg.sto", table_from_columns(time, columns, name="leg"))
    kinematics = MarkerKinematics(model, model.marker_names)
    q = np.column_stack([columns[name] for name in kinematics.free_names])
    write_trc(folder / "leg.trc", MarkerTable(time=time, names=tuple(model.marker_names),
                                              positions=kinematics.marker_positions(q), units="m"))
    rng = np.random.default_rng(0)
    (folder / "acts").mkdir()
    for trial in ("trial_1", "trial_2"):
        data = {f"m{k}": rng.uniform(0.01, 1.0, 30) for k in range(4)}
        write_storage(folder / "acts" / f"{trial}.sto", table_from_columns(np.linspace(0, 1, 30), data, name=trial))
    (folder / "tree" / "jmp" / "plots").mkdir(parents=True)
    (folder / "tree" / "jmp" / "plots" / "a.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    (folder / "tree" / "pipeline_state.json").write_text(json.dumps(
        {"stages": {"jmp": {"kind": "jmp", "results_directory": "jmp"}}}))
    write_osimx(folder / "leg.osimx", OsimxModel(name="leg", associated_osim_model="leg.osim"))
    (folder / "bad_jmp").mkdir()
    (folder / "bad_jmp" / "jmp_results.json").write_text("{}")  # detected as JMP results; its figures fail
    (folder / "empty").mkdir()
    (folder / "treat" / "IKData").mkdir(parents=True)
    t = np.linspace(0.0, 1.0, 5)
    write_storage(folder / "treat" / "arm1_states.sto", table_from_columns(t, {"q": 0.1 * t, "q_u": 0.1 + 0 * t}))
    write_storage(folder / "treat" / "arm1_torqueControls.sto", table_from_columns(t, {"q": np.sin(t)}))
    return folder


@pytest.fixture
def work(source: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A writable copy of the inputs, the current folder; ``out/`` exists, ``nodir/`` does not."""
    shutil.copytree(source, tmp_path, dirs_exist_ok=True)
    (tmp_path / "out").mkdir()
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _fails(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``nmsm argv``, expect exit 1 with one ``nmsm: error:`` line; return it."""
    capsys.readouterr()
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith("nmsm: error: ") and "Traceback" not in err, err
    return err


def _bytes(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


# ---- P2: an output that is an input ----------------------------------------------------------
INPUT_AS_OUTPUT = {
    "id -o MODEL": (["id", "leg.osim", "leg.sto", "-o", "leg.osim"], "the input model (MODEL)"),
    "id -o MOTION": (["id", "leg.osim", "leg.sto", "-o", "leg.sto"], "the input motion (MOTION)"),
    "id -o ./MOTION spelled otherwise": (["id", "leg.osim", "leg.sto", "-o", "out/../leg.sto"], "the input motion"),
    "markers -o MOTION": (["markers", "leg.osim", "leg.sto", "-o", "leg.sto"], "the input motion (MOTION)"),
    "ik -o MARKERS": (["ik", "leg.osim", "leg.trc", "-o", "leg.trc"], "the marker file (MARKERS.trc)"),
    "ik --errors MODEL": (["ik", "leg.osim", "leg.trc", "-o", "out/ik.mot", "--errors", "leg.osim"],
                          "the input model (MODEL)"),
    "vaf --output ACT": (["vaf", "acts/trial_1.sto", "--output", "acts/trial_1.sto"], "an activation file"),
    "vaf --output a file of an activation folder": (["vaf", "acts", "--output", "acts/trial_2.sto"],
                                                    "an activation file (trial_2.sto)"),
    "export -o its .osimx": (["export", "leg.osimx", "-o", "leg.osimx"], "the input .osimx"),
    "export -o the associated model": (["export", "leg.osimx", "-o", "leg.osim"], "the model the .osimx names"),
}


@pytest.mark.parametrize("case", list(INPUT_AS_OUTPUT))
def test_an_output_that_is_an_input_is_refused(case: str, work: Path, capsys) -> None:
    argv, what = INPUT_AS_OUTPUT[case]
    before = _bytes(work)
    err = _fails(argv, capsys)
    option = "--errors" if "--errors" in argv else "--output" if "--output" in argv else "-o"
    assert f"the output file ({option}) is {what}" in err and "writing it would overwrite an input" in err
    assert _bytes(work) == before


@pytest.mark.parametrize("link", ["symlink", "hardlink"])
def test_a_link_to_an_input_is_refused(link: str, work: Path, capsys) -> None:
    (os.symlink if link == "symlink" else os.link)(work / "leg.osim", work / "out" / "link.osim")
    before = _bytes(work)
    err = _fails(["id", "leg.osim", "leg.sto", "-o", "out/link.osim"], capsys)
    assert "out/link.osim: the output file (-o) is the input model (MODEL): writing it would overwrite an input " \
           "(expected another output file name)" in err
    assert _bytes(work) == before


def test_ik_settings_output_that_is_the_marker_file_is_refused(work: Path, capsys) -> None:
    (work / "ik.xml").write_text(
        "<OpenSimDocument><InverseKinematicsTool><marker_file>leg.trc</marker_file>"
        "<output_motion_file>leg.trc</output_motion_file></InverseKinematicsTool></OpenSimDocument>")
    before = _bytes(work)
    err = _fails(["ik", "leg.osim", "--ik-settings", "ik.xml"], capsys)
    assert "leg.trc: the output file (<output_motion_file> of " in err and "ik.xml) is the marker file" in err
    assert _bytes(work) == before


def test_ik_output_and_errors_must_differ(work: Path, capsys) -> None:
    err = _fails(["ik", "leg.osim", "leg.trc", "-o", "out/ik.mot", "--errors", "out/ik.mot"], capsys)
    assert "out/ik.mot: --errors and -o name the same file" in err
    assert not (work / "out" / "ik.mot").exists()


def test_surrogate_output_that_is_its_model_is_refused(shared_data: Path, tmp_path: Path, capsys) -> None:
    model = tmp_path / "RightLegAndPelvis.osim"
    shutil.copyfile(shared_data / KICK / "RightLegAndPelvis.osim", model)
    before = model.read_bytes()
    err = _fails(["surrogate", "--model", str(model), "--data-dir", str(shared_data / KICK / "surrogateData"),
                  "--coordinates", "knee_angle_r", "ankle_angle_r", "--degree", "2", "-o", str(model)], capsys)
    assert "the output file (--output) is the --model file: writing it would overwrite an input" in err
    assert model.read_bytes() == before


def test_surrogate_output_inside_its_data_folder_is_refused(shared_data: Path, tmp_path: Path, capsys) -> None:
    data = tmp_path / "surrogateData"
    shutil.copytree(shared_data / KICK / "surrogateData", data)
    victim = sorted((data / "IKData").iterdir())[0]
    before = victim.read_bytes()
    err = _fails(["surrogate", "--model", str(shared_data / KICK / "RightLegAndPelvis.osim"), "--data-dir", str(data),
                  "--coordinates", "knee_angle_r", "-o", str(victim)], capsys)
    assert "the output file (--output) already exists inside the --data-dir folder" in err
    assert victim.read_bytes() == before


def test_muscle_analysis_never_writes_over_its_motion(work: Path, capsys) -> None:
    (work / "MA" / "leg").mkdir(parents=True)
    shutil.copyfile(work / "leg.sto", work / "MA" / "leg" / "leg_Length.sto")
    err = _fails(["muscle-analysis", "leg.osim", "MA/leg/leg_Length.sto", "-o", "MA", "--trial", "leg"], capsys)
    assert "the output would overwrite the input motion (MOTION)" in err


# ---- P8: output folders ---------------------------------------------------------------------
MISSING_FOLDER = {
    "id": ["id", "none.osim", "none.sto", "-o", "nodir/id.sto"],
    "markers": ["markers", "none.osim", "none.sto", "-o", "nodir/m.trc"],
    "ik": ["ik", "none.osim", "none.trc", "-o", "nodir/ik.mot"],
    "surrogate": ["surrogate", "--model", "none.osim", "--data-dir", "empty", "--coordinates", "q",
                  "-o", "nodir/s.json"],
    "vaf": ["vaf", "acts", "--output", "nodir/v.csv"],
    "report": ["report", "tree", "-o", "nodir/r.html"],
    "export": ["export", "none.osimx", "--model", "leg.osim", "-o", "nodir/x.osim"],
    "muscle-analysis": ["muscle-analysis", "none.osim", "none.sto", "-o", "nodir/MA"],
    "plot": ["plot", "bad_jmp", "-o", "nodir/p"],
}


@pytest.mark.parametrize("command", list(MISSING_FOLDER))
def test_a_missing_output_folder_is_refused_before_computing(command: str, work: Path, capsys) -> None:
    """No command creates missing folders above its output (a typo must not make folders);
    the inputs here do not even exist: the output is checked first."""
    err = _fails(MISSING_FOLDER[command], capsys)
    option = "--output" if command in ("surrogate", "vaf") else "-o"
    kind = "folder" if command in ("muscle-analysis", "plot") else "file"
    assert f"cannot write the output {kind}: its folder nodir does not exist (expected {option} naming a {kind} " \
           "in an existing folder: create nodir first or fix the path)" in err
    assert not (work / "nodir").exists()


FOLDER_FOR_A_FILE = {
    "id": (["id", "none.osim", "none.sto", "-o", "out"], "-o", "out/id.sto"),
    "markers": (["markers", "none.osim", "none.sto", "-o", "out"], "-o", "out/markers.trc"),
    "ik": (["ik", "none.osim", "none.trc", "-o", "out"], "-o", "out/ik.mot"),
    "ik --errors": (["ik", "none.osim", "none.trc", "-o", "out/ik.mot", "--errors", "out"], "--errors",
                    "out/marker_errors.sto"),
    "surrogate": (["surrogate", "--model", "none.osim", "--data-dir", "empty", "--coordinates", "q", "-o", "out"],
                  "--output", "out/surrogateMuscles.json"),
    "vaf": (["vaf", "acts", "--output", "out"], "--output", "out/vaf.csv"),
    "report": (["report", "tree", "-o", "out"], "-o", "out/report.html"),
    "export": (["export", "none.osimx", "--model", "leg.osim", "-o", "out"], "-o", "out/model.osim"),
}


@pytest.mark.parametrize("command", list(FOLDER_FOR_A_FILE))
def test_a_folder_where_a_file_is_expected_is_refused_before_computing(command: str, work: Path, capsys) -> None:
    argv, option, example = FOLDER_FOR_A_FILE[command]
    err = _fails(argv, capsys)
    assert f"out: {option} names a folder, not a file (expected the name of the file to write, e.g. {example})" in err


def test_vaf_prints_nothing_before_refusing_a_folder(work: Path, capsys) -> None:
    capsys.readouterr()
    assert main(["vaf", "acts", "--output", "out"]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and "--output names a folder" in captured.err


@pytest.mark.parametrize("command", ["muscle-analysis", "plot"])
def test_a_file_where_a_folder_is_expected_is_refused(command: str, work: Path, capsys) -> None:
    (work / "out" / "x.txt").write_text("keep\n")
    argv = (["muscle-analysis", "none.osim", "none.sto", "-o", "out/x.txt"] if command == "muscle-analysis"
            else ["plot", "bad_jmp", "-o", "out/x.txt"])
    err = _fails(argv, capsys)
    assert "out/x.txt: -o names a file, not a folder" in err
    assert (work / "out" / "x.txt").read_text() == "keep\n"


# ---- P10: no partial output -----------------------------------------------------------------
def test_ik_checks_errors_path_before_writing_the_motion(work: Path, capsys) -> None:
    err = _fails(["ik", "leg.osim", "leg.trc", "-o", "out/ik.mot", "--errors", "nodir/err.sto"], capsys)
    assert "nodir/err.sto: cannot write the output file" in err and "--errors naming a file" in err
    assert not (work / "out" / "ik.mot").exists()


@pytest.mark.parametrize("treatment", ["empty", "none"])
def test_export_checks_the_treatment_before_writing_the_model(treatment: str, work: Path, capsys) -> None:
    _fails(["export", "leg.osimx", "-o", "out/x.osim", "--treatment", treatment, "--loads", "out/l.xml"], capsys)
    assert sorted(p.name for p in (work / "out").iterdir()) == []


def test_export_loads_need_treatment(work: Path, capsys) -> None:
    err = _fails(["export", "leg.osimx", "-o", "out/x.osim", "--loads", "out/l.xml"], capsys)
    assert "--loads needs --treatment" in err
    assert sorted(p.name for p in (work / "out").iterdir()) == []


def test_options_that_would_be_ignored_are_refused(work: Path, capsys) -> None:
    err = _fails(["export", "leg.osimx", "-o", "out/x.osim", "--trial", "walk"], capsys)
    assert "--trial names a trial of --treatment's results" in err
    err = _fails(["surrogate", "--model", "leg.osim", "--data-dir", "data", "--coordinates", "knee_angle_r",
                  "-o", "out/s.json", "--write-samples", "out/samples"], capsys)
    assert "--write-samples keeps the poses sampled around a --motion" in err
    assert sorted(p.name for p in (work / "out").iterdir()) == []


def test_plot_removes_the_folder_it_created_when_it_draws_nothing(work: Path, capsys) -> None:
    capsys.readouterr()
    assert main(["plot", "bad_jmp", "-o", "out/p"]) == 1
    assert "no figures" in capsys.readouterr().out
    assert not (work / "out" / "p").exists()
    (work / "out" / "kept").mkdir()
    assert main(["plot", "bad_jmp", "-o", "out/kept"]) == 1
    assert (work / "out" / "kept").is_dir()  # it was there before


WRITES = {
    "id": (["id", "leg.osim", "leg.sto", "-o", "out/f.sto"], "out/f.sto"),
    "markers": (["markers", "leg.osim", "leg.sto", "-o", "out/f.trc"], "out/f.trc"),
    "ik": (["ik", "leg.osim", "leg.trc", "-o", "out/f.mot"], "out/f.mot"),
    "vaf": (["vaf", "acts", "--output", "out/f.csv"], "out/f.csv"),
    "report": (["report", "tree", "-o", "out/f.html"], "out/f.html"),
    "export": (["export", "leg.osimx", "-o", "out/f.osim"], "out/f.osim"),
}


@pytest.mark.parametrize("command", list(WRITES))
def test_a_failed_write_leaves_the_earlier_file(command: str, work: Path, capsys,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    argv, output = WRITES[command]
    (work / output).write_text("earlier\n")

    def full_disk(fd: int) -> None:
        raise OSError(28, "No space left on device")

    with monkeypatch.context() as patch:
        patch.setattr(os, "fsync", full_disk)
        err = _fails(argv, capsys)
    assert f"{output}: cannot write the output file: No space left on device" in err
    assert (work / output).read_text() == "earlier\n"
    assert [p.name for p in (work / "out").iterdir()] == [Path(output).name]  # no temporary file left
    assert main(argv) == 0 and (work / output).read_text() != "earlier\n"


# ---- several files: all or nothing ----------------------------------------------------------
def _second_call_fails(patch: pytest.MonkeyPatch, owner: object, name: str, error: str,
                       path_argument: int = 0, call: int = 2) -> list[Path]:
    """Make the second (``call``-th) call of ``owner.name`` raise: "disk", a full disk writing
    the path it was given (its argument ``path_argument``); "stop", Ctrl-C. Returns the paths
    given."""
    real = getattr(owner, name)
    paths: list[Path] = []

    def failing(*args, **kwargs):
        path = Path(args[path_argument])
        paths.append(path)
        if len(paths) == call:
            raise KeyboardInterrupt if error == "stop" else OSError(28, "No space left on device", str(path))
        return real(*args, **kwargs)

    patch.setattr(owner, name, failing)
    return paths


def _listing(folder: Path, *, folder_times: bool = False) -> dict[str, tuple[bool, int, bytes]]:
    """Every path below ``folder`` (hidden ones too): (is a folder, mtime in ns, bytes). A
    folder's mtime (changed by any file created and removed in it, e.g. a staging folder)
    only with ``folder_times``."""
    return {str(p.relative_to(folder)): (p.is_dir(), p.stat().st_mtime_ns if folder_times or not p.is_dir() else 0,
                                         b"" if p.is_dir() else p.read_bytes())
            for p in sorted(folder.rglob("*"))}


def _ends(argv: list[str], error: str, capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``nmsm argv``, which fails on a full disk (exit status 1) or is stopped (130);
    returns what it printed (stdout and stderr)."""
    capsys.readouterr()
    assert main(argv) == (130 if error == "stop" else 1)
    captured = capsys.readouterr()
    return captured.out + captured.err


@pytest.mark.parametrize("error", ["disk", "stop"])
@pytest.mark.parametrize("earlier", [False, True])
def test_muscle_analysis_writes_all_its_files_or_none(error: str, earlier: bool, work: Path, capsys,
                                                      monkeypatch: pytest.MonkeyPatch) -> None:
    """The second of the 13 files fails: no file of the run is left (not the first, not a
    staged one), an earlier run's file is unchanged, the folders the run created are removed."""
    import nmsm.model.muscle_analysis as muscle_analysis

    if earlier:
        (work / "out" / "MA" / "leg").mkdir(parents=True)
        (work / "out" / "MA" / "leg" / "leg_Length.sto").write_text("earlier\n")
    before = _listing(work / "out")
    argv = ["muscle-analysis", "leg.osim", "leg.sto", "-o", "out/MA"]
    with monkeypatch.context() as patch:
        paths = _second_call_fails(patch, muscle_analysis, "write_storage", error)
        printed = _ends(argv, error, capsys)
    assert [p.name for p in paths] == ["leg_Length.sto", "leg_Velocity.sto"]
    if error == "disk":
        assert "nmsm: error: out/MA/leg/leg_Velocity.sto: cannot write the output file: No space left on device" \
               in printed, printed
    assert _listing(work / "out") == before
    assert main(["muscle-analysis", "leg.osim", "leg.sto", "-o", "out/MA"]) == 0
    written = sorted(p.name for p in (work / "out" / "MA" / "leg").iterdir())
    assert len(written) == 13 and all(name.startswith("leg_") for name in written), written
    assert (work / "out" / "MA" / "leg" / "leg_Length.sto").read_text() != "earlier\n"


@pytest.mark.parametrize("error", ["disk", "stop"])
@pytest.mark.parametrize("earlier", [False, True])
@pytest.mark.parametrize("output", [None, "out/figures"])
def test_plot_draws_a_folder_s_figures_all_or_none(error: str, earlier: bool, output: str | None, work: Path,
                                                   capsys, monkeypatch: pytest.MonkeyPatch) -> None:
    """The second of the treatment folder's two figures fails: neither is left, an earlier
    figure is unchanged, the figure folder the run created is removed."""
    import matplotlib.figure

    plots = work / "treat" / "plots" if output is None else work / output
    if earlier:
        plots.mkdir()
        (plots / "arm1_kinematics.png").write_bytes(b"earlier")
    before = _listing(work)
    argv = ["plot", "treat"] + ([] if output is None else ["-o", output])
    with monkeypatch.context() as patch:
        paths = _second_call_fails(patch, matplotlib.figure.Figure, "savefig", error, path_argument=1)
        printed = _ends(argv, error, capsys)
    assert [p.name for p in paths] == ["arm1_kinematics.png", "arm1_controls.png"]
    if error == "disk":
        where = Path(output) if output else Path("treat") / "plots"
        assert f"no figures (InputError: {where / 'arm1_controls.png'}: cannot write the output file: No space " \
               "left on device" in printed, printed
    assert _listing(work) == before
    assert main(argv) == 0
    assert sorted(p.name for p in plots.iterdir()) == ["arm1_controls.png", "arm1_kinematics.png"]
    assert (plots / "arm1_kinematics.png").read_bytes() != b"earlier"


@pytest.mark.parametrize("error", ["disk", "stop"])
@pytest.mark.parametrize("failing", ["samples", "surrogate"])
def test_surrogate_writes_its_file_and_the_samples_all_or_none(error: str, failing: str, work: Path, capsys,
                                                               monkeypatch: pytest.MonkeyPatch) -> None:
    """``--write-samples`` fails at its third file (MAData's velocities, after IKData and the
    lengths), or the surrogate file fails after every sample is written: no sample file is
    left, the earlier surrogate file is unchanged, the samples folder the run created is
    removed. (OpenSim's sampling is replaced by a knee muscle whose length is linear.)"""
    import nmsm.model.muscle_analysis as muscle_analysis
    import nmsm.tools.surrogate.sampling as sampling
    from nmsm.model.surrogate import GeometrySamples, SurrogateModel

    def poses(model_file, motion, **options):
        return ("knee_angle",), np.random.default_rng(0).uniform(-1.0, 0.0, (60, 1))

    def samples(model_file, coordinates, q, surrogate_coordinates, **options):
        return GeometrySamples(surrogate_coordinates, ("knee_muscle",), q, 0.3 - 0.04 * q, np.full((len(q), 1, 1), 0.04))

    monkeypatch.setattr(sampling, "poses_around_motion", poses)
    monkeypatch.setattr(sampling, "opensim_samples", samples)
    (work / "out" / "s.json").write_text("earlier\n")
    before = _listing(work / "out")
    argv = ["surrogate", "--model", "leg.osim", "--motion", "leg.sto", "--coordinates", "knee_angle",
            "-o", "out/s.json", "--write-samples", "out/samples"]
    with monkeypatch.context() as patch:
        if failing == "samples":
            paths = _second_call_fails(patch, muscle_analysis, "write_storage", error)
            target = "out/samples/MAData/leg/leg_Velocity.sto"
        else:
            paths = _second_call_fails(patch, SurrogateModel, "save", error, path_argument=1, call=1)
            target = "out/s.json"
        printed = _ends(argv, error, capsys)
    assert paths and paths[-1].name == Path(target).name
    if error == "disk":
        assert f"nmsm: error: {target}: cannot write the output file: No space left on device" in printed, printed
    assert _listing(work / "out") == before
    assert main(argv) == 0
    written = sorted(str(p.relative_to(work / "out")) for p in (work / "out").rglob("*") if p.is_file())
    assert written == ["s.json", "samples/IKData/leg.sto", "samples/MAData/leg/leg_Length.sto",
                       "samples/MAData/leg/leg_MomentArm_knee_angle.sto"], written
    assert SurrogateModel.load(work / "out" / "s.json").muscle_names == ("knee_muscle",)


# ---- report: the tree it reads is left as it was ---------------------------------------------
@pytest.mark.parametrize("output", ["out/r.html", None])
def test_report_leaves_the_results_tree_untouched(output: str | None, work: Path, capsys) -> None:
    """The treatment folder has no figures: the report draws them outside the tree and embeds
    them; no path, byte or time of the tree changes (but for the report itself when it goes
    into the tree, the default)."""
    before = _listing(work / "treat", folder_times=output is not None)
    capsys.readouterr()
    assert main(["report", "treat"] + (["-o", output] if output else [])) == 0
    page = work / (output or "treat/report.html")
    assert capsys.readouterr().out == f"wrote {Path(output or 'treat/report.html')}\n"
    after = _listing(work / "treat", folder_times=output is not None)
    if output is None:
        assert after.pop("report.html")[2] == page.read_bytes()
    assert after == before
    assert page.read_text().count("data:image/png;base64,") == 2  # the two figures, embedded

"""``nmsm example``: the synthetic subject and the first stages (default suite), the whole
pipeline (slow); the report and plots of its results tree; the commands."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.examples.example_run import run_example
from nmsm.examples.subject import TRIAL_WINDOW, read_truth
from nmsm.tools.pipeline.runner import UP_TO_DATE


@pytest.fixture(scope="module")
def early(tmp_path_factory):
    """The example up to preprocessing (subject generation, JMP, the passive trials' and the
    gait trial's analyses, preprocessing)."""
    folder = tmp_path_factory.mktemp("example")
    return run_example(folder, until="preprocess", log=None)


def test_subject_is_consistent(early) -> None:
    truth = read_truth(early.folder / "truth" / "truth.json")
    simulation = np.load(early.folder / "truth" / "simulation.npz")
    window = (simulation["time"] >= TRIAL_WINDOW[0]) & (simulation["time"] <= TRIAL_WINDOW[1])
    # the foot is loaded in the trial, and the muscles act
    assert simulation["force"][window, 1].max() > 200.0
    assert simulation["a"][window].max() > 0.3
    # the analysis stage's inverse dynamics (IK of the markers on JMP's model, ground
    # reactions from the force-plate file) reproduces the simulation's muscle moments
    from nmsm.io.storage import read_storage

    moments = read_storage(early.results / "analysis" / "IDData" / "gait.sto")
    keep = (moments.time >= TRIAL_WINDOW[0]) & (moments.time <= TRIAL_WINDOW[1])
    for k, coordinate in enumerate(truth["coordinates"]):
        expected = np.interp(moments.time[keep], simulation["time"], simulation["muscle_moments"][:, k])
        rms = np.sqrt(np.mean((moments.column(f"{coordinate}_moment")[keep] - expected) ** 2))
        scale = np.sqrt(np.mean(expected**2))
        assert rms < 0.05 * scale + 1.0, f"{coordinate}: ID vs simulated moments {rms:.2f} N m RMS"


def test_mtp_model_at_the_truth_reproduces_the_data(early) -> None:
    """MTP's own model chain with every muscle parameter at its true value, on the
    preprocessed trial, gives the preprocessed ID moments (what is left: filtered ID and
    activations the activation dynamics cannot follow exactly). A 0.2 s EMG padding made the
    delayed spline extrapolate into an activation transient: 242 N m RMS at the hip."""
    from nmsm.examples.subject_consistency import mtp_at_truth
    from nmsm.examples.subject_settings import PREPROCESSED_TRIAL

    fit = mtp_at_truth(early.folder, early.results / "preprocess", PREPROCESSED_TRIAL)
    scale = np.sqrt(np.mean(fit.measured**2, axis=0))
    for k, coordinate in enumerate(fit.coordinates):
        assert fit.moment_rms[k] < 0.1 * scale[k] + 1.0, f"{coordinate}: {fit.moment_rms[k]:.1f} N m RMS at the truth"
    assert fit.activation_rms.max() < 0.05, dict(zip(fit.muscles, fit.activation_rms.round(3)))


def test_jmp_recovers_the_joint_frames(early) -> None:
    jmp = [c for c in early.checks if c.stage == "JMP"]
    assert len(jmp) == 6 and all(c.ok for c in jmp), early.text
    assert max(abs(c.error) for c in jmp) < np.radians(0.25)


def test_preprocessed_trial_layout(early) -> None:
    data = early.results / "preprocess"
    for folder in ("IKData", "IDData", "EMGData", "GRFData"):
        assert (data / folder / "gait_1.sto").is_file()
    assert (data / "MAData" / "gait_1" / "gait_1_MomentArm_knee_angle_r.sto").is_file()
    from nmsm.io.storage import read_storage

    emg = read_storage(data / "EMGData" / "gait_1.sto")
    ik = read_storage(data / "IKData" / "gait_1.sto")
    assert ik.n_rows == 101 and emg.n_rows > 101
    assert emg.time[0] < ik.time[0] - 0.19 and emg.time[-1] > ik.time[-1] + 0.19
    assert 0.0 <= emg.data.min() and emg.data.max() <= 1.0 + 1e-9


def test_running_again_redoes_nothing(early) -> None:
    again = run_example(early.folder, until="preprocess", log=None)
    state = json.loads((early.results / "pipeline_state.json").read_text())
    assert set(state["stages"]) == {"jmp", "passive", "analysis", "preprocess"}
    assert again.checks == early.checks
    from nmsm.tools.pipeline.runner import run_pipeline_file

    run = run_pipeline_file(early.folder / "pipeline.xml", log=None)
    assert {s.status for s in run.stages} == {UP_TO_DATE}


def test_report_and_plots_of_the_tree(early, tmp_path: Path) -> None:
    from nmsm.plots.cli import plot_tree, results_folders
    from nmsm.report.html import write_report

    found = results_folders(early.results)
    assert ("jmp", early.results / "jmp") in found
    figures, errors = plot_tree(early.results, tmp_path / "figures", log=lambda text: None)
    assert not errors and figures[early.results / "jmp"]
    page = write_report(early.results, tmp_path / "report.html", checks=early.checks, log=None).read_text()
    assert "Known-answer comparison" in page and "knee_r parent orientation x" in page
    assert "marker distance errors" in page and "IK, ID and muscle analysis" in page
    assert page.count("data:image/png;base64,") >= 1


def test_report_leaves_the_results_tree_untouched(early, tmp_path: Path, capsys) -> None:
    """``nmsm report`` on a copy of the example's tree without figures: every stage's figures
    are drawn outside the tree and embedded; no path, byte or modification time of the tree
    changes. The example's own report (written by run_example) drew none into the tree either."""
    import shutil

    assert not list(early.results.rglob("plots"))
    tree = tmp_path / "results"
    shutil.copytree(early.results, tree, symlinks=True)

    def listing() -> dict[str, tuple[bool, int, bytes]]:
        return {str(p.relative_to(tree)): (p.is_dir(), p.stat().st_mtime_ns, b"" if p.is_dir() else p.read_bytes())
                for p in sorted(tree.rglob("*"))}

    before = listing()
    root_time = tree.stat().st_mtime_ns
    capsys.readouterr()
    assert main(["report", str(tree), "-o", str(tmp_path / "r.html")]) == 0
    assert listing() == before and tree.stat().st_mtime_ns == root_time
    page = (tmp_path / "r.html").read_text()
    assert page.count("data:image/png;base64,") >= 2 and "jmp_summary.png" in page


def test_commands(early, capsys) -> None:
    assert main(["pipeline", str(early.folder / "pipeline.xml"), "--check"]) == 0
    out = capsys.readouterr().out
    assert "jmp" in out and "up to date" in out
    assert main(["report", str(early.results), "-o", str(early.folder / "r.html")]) == 0
    assert (early.folder / "r.html").is_file()
    assert main(["example", "nonsense", "--folder", str(early.folder)]) == 1
    assert "no example stage 'nonsense'" in capsys.readouterr().err
    from nmsm.examples.subject_settings import STAGES

    with pytest.raises(SystemExit):
        main(["example", "--help"])
    listed = " ".join(capsys.readouterr().out.split())
    assert "(" + ", ".join(STAGES) + ")" in listed, listed  # the help names every stage, in order


@pytest.mark.slow
def test_whole_example(tmp_path: Path) -> None:
    """Lab data to treatment: every stage runs; JMP, MTP (moment fit, the lengths MTLI fits
    to the passive trials, delays and activation time constants of the active muscles), NCP
    (against MTP's activations and the truth), GCP (resting spring length, dynamic friction,
    spring constants, ground reactions) and TO's tracking are within their tolerances; VO,
    anchored at the TO's initial state, reproduces the TO."""
    outcome = run_example(tmp_path, log=None)
    print(outcome.text)
    assert set(outcome.stage_times) == {"jmp", "passive", "analysis", "preprocess", "mtp", "ncp", "gcp", "surrogate",
                                        "to", "vo", "do"}
    assert all(c.ok for c in outcome.checks if c.stage == "JMP")
    assert all(c.ok for c in outcome.checks if c.stage == "MTP" and c.ok is not None)
    assert sum(c.stage == "MTP" and c.ok is not None for c in outcome.checks) >= 25
    assert all(c.ok for c in outcome.checks if c.stage == "NCP" and c.ok is not None)
    gcp = [c for c in outcome.checks if c.stage == "GCP" and c.ok is not None]
    assert len(gcp) == 9 and all(c.ok for c in gcp), [(c.quantity, c.error) for c in gcp if not c.ok]
    assert all(c.ok for c in outcome.checks if c.stage == "TO")
    verification = [c for c in outcome.checks if c.stage == "VO"]
    assert verification and all(abs(c.recovered) < 0.25 for c in verification), [c.recovered for c in verification]
    assert any(c.stage == "DO" for c in outcome.checks)
    assert (outcome.results / "report.html").is_file()


def test_mtp_and_ncp_stages_converge(early, tmp_path) -> None:
    """MTLI fits the lengths to the passive trials and both MTP tasks (lengths fixed)
    converge; NCP (5 synergies for 8 muscles: flat directions) ends before the
    ``<max_iterations>`` of its settings (at its tolerance or its acceptable level)."""
    import re
    import shutil

    folder = tmp_path / "example"
    shutil.copytree(early.folder, folder)
    outcome = run_example(folder, until="ncp", log=None)
    summary = (folder / "results" / "mtp" / "mtpSummary.txt").read_text()
    assert re.search(r"task 1: Solve_Succeeded", summary) and re.search(r"task 2: Solve_Succeeded", summary), summary
    lengths = [c for c in outcome.checks if c.stage == "MTP" and c.quantity.endswith("length")]
    assert len(lengths) == 16 and all(c.ok for c in lengths), [(c.quantity, c.error) for c in lengths]
    log = (folder / "results" / "ncp" / "commandWindowOutput.txt").read_text()
    found = re.search(r"ipopt: (\w+) after (\d+) iterations", log)
    assert found is not None, log
    assert found.group(1) in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
    pipeline = (folder / "pipeline.xml").read_text()
    limit = re.search(r'<Stage name="ncp">.*?<max_iterations>(\d+)</max_iterations>', pipeline, re.DOTALL)
    assert limit is not None, pipeline
    assert int(found.group(2)) < int(limit.group(1))


#: what the browser test reads of the page, as JSON: title, the status table's and the first
#: figure's top edges (CSS px from the top of the first screen), whether every image decoded
PAGE_FACTS = """(() => {
  const box = (el) => el ? el.getBoundingClientRect().top : null;
  const images = Array.from(document.images);
  const status = document.querySelector('table.status');
  const figure = document.querySelector('.figures img');
  return {title: document.title, h1: document.querySelector('h1').textContent, screen: window.innerHeight,
          status_top: box(status), status_rows: status ? status.rows.length - 1 : 0,
          status_links: Array.from(document.querySelectorAll('table.status a')).map(a => a.getAttribute('href')),
          figure_top: box(figure), figure_width: figure ? figure.getBoundingClientRect().width : 0,
          images: images.length, decoded: images.filter(i => i.complete && i.naturalWidth > 0).length,
          pre: document.querySelectorAll('details pre').length,
          anchors: Array.from(document.querySelectorAll('section[id]')).map(s => s.id)};
})()"""


def test_report_in_a_browser(early, tmp_path: Path, chromium: str) -> None:
    """The example's report in headless Chromium (1280 x 900): no error while loading; the
    status table (every stage, linked to its section) and a decoded figure in the first screen."""
    from browser_page import load_page

    from nmsm.report.html import write_report

    page = write_report(early.results, tmp_path / "report.html", checks=early.checks, log=None,
                        title="nmsm example: synthetic subject")
    loaded = load_page(chromium, page, PAGE_FACTS)
    (tmp_path / "first_screen.png").write_bytes(loaded.screenshot)
    facts = loaded.value
    assert loaded.errors == [], loaded.errors
    assert facts["title"] == facts["h1"] == "nmsm example: synthetic subject"
    stages = list(json.loads((early.results / "pipeline_state.json").read_text())["stages"])
    assert facts["status_rows"] == len(stages)
    assert 0 <= facts["status_top"] < facts["screen"]
    for link in facts["status_links"]:
        assert link[1:] in facts["anchors"], link
    assert "#stage-jmp" in facts["status_links"]
    assert facts["figure_top"] is not None and 0 < facts["figure_top"] < facts["screen"] - 100, facts
    assert facts["figure_width"] >= 400 and facts["images"] >= 2 and facts["decoded"] == facts["images"]
    assert facts["pre"] >= 1  # summaries are preformatted text
    assert loaded.screenshot[:8] == b"\x89PNG\r\n\x1a\n"


def test_pipeline_stages_print_start_lines(early, tmp_path: Path, capsys) -> None:
    """The analysis, preprocessing and surrogate stages print the tools' start line
    (nmsm.core.console) when console output is on, and nothing when it is off."""
    from nmsm.core.console import console_output
    from nmsm.examples.subject_settings import PREPROCESSED_TRIAL
    from nmsm.tools.pipeline import analysis, preprocess_stage, surrogate_stage

    results = early.results
    model = results / "jmp" / "personalized.osim"
    surrogate = tmp_path / "surrogate.xml"
    surrogate.write_text(f"""<NMSMPipelineDocument Version="1.5.3"><SurrogateDataTool>
        <results_directory>{tmp_path / 'surrogate'}</results_directory>
        <input_model_file>{model}</input_model_file>
        <data_directory>{results / 'preprocess'}</data_directory>
        <trial_name>{PREPROCESSED_TRIAL}</trial_name>
        <coordinate_list>knee_angle_r</coordinate_list>
        <samples_per_frame>2</samples_per_frame>
        <frame_stride>25</frame_stride>
      </SurrogateDataTool></NMSMPipelineDocument>""", encoding="utf-8")
    surrogate_stage.run_settings(surrogate)
    assert capsys.readouterr().out == ""  # library calls stay silent
    with console_output():
        analysis.run_settings(results / "analysis.xml", results_directory=tmp_path / "analysis")
        preprocess_stage.run_settings(results / "preprocess.xml", results_directory=tmp_path / "preprocessed")
        surrogate_stage.run_settings(surrogate, results_directory=tmp_path / "surrogate_2")
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("nmsm ")]
    assert [line.split(":")[0] for line in lines] == ["nmsm analysis", "nmsm preprocess", "nmsm surrogate"]
    assert lines[0].startswith("nmsm analysis: settings analysis.xml; model ") and "; problem IK of " in lines[0]
    assert "muscle analysis of 8 muscles" in lines[0]
    assert lines[1].startswith("nmsm preprocess: settings preprocess.xml; model ") and " rows each" in lines[1]
    assert lines[2].startswith(f"nmsm surrogate: settings surrogate.xml; model personalized.osim; "
                               f"trials {PREPROCESSED_TRIAL}; problem ")
    assert " per frame) varying 1 coordinates" in lines[2]

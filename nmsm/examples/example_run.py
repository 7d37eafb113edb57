"""``nmsm example [STAGE]``: the synthetic subject from lab data to treatment, with answers.

1. Generate the subject (:func:`nmsm.examples.subject.make_subject`) into
   ``<folder>/subject`` and ``<folder>/truth``, unless it is already there;
2. write ``<folder>/pipeline.xml`` (:mod:`nmsm.examples.subject_settings`) with the stages
   up to ``until`` and run it (:mod:`nmsm.tools.pipeline.runner`: finished stages are kept,
   so running again only redoes what changed);
3. compare what each stage found with the truth (:mod:`nmsm.examples.subject_recovery`)
   and write ``<folder>/results/report.html`` (:mod:`nmsm.report`) with the comparison.

Nothing outside the installed package is needed (no OpenSim, no data files).
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import attrs

from nmsm.examples import subject_recovery as recovery
from nmsm.examples.subject_settings import PLANTARFLEXOR_STRENGTH, PLANTARFLEXORS, PREPROCESSED_TRIAL, STAGES


@attrs.frozen
class ExampleOutcome:
    """A finished example: the comparison rows, the report text, where things are."""

    folder: Path
    results: Path
    checks: tuple[recovery.Check, ...]
    text: str
    wall_time: float
    stage_times: dict[str, float]

    @property
    def all_within_tolerance(self) -> bool:
        return all(c.ok is not False for c in self.checks)


def _checks(folder: Path, results: Path, ran: set[str]) -> list[recovery.Check]:
    from nmsm.examples.subject import read_truth

    truth_dir = folder / "truth"
    truth = read_truth(truth_dir / "truth.json")
    out: list[recovery.Check] = []
    if "jmp" in ran:
        out += recovery.jmp_checks(truth, results / "jmp")
    if "mtp" in ran:
        out += recovery.mtp_checks(truth, truth_dir, results / "mtp")
    if "ncp" in ran:
        out += recovery.ncp_checks(truth, truth_dir, results / "ncp", results / "mtp")
    if "gcp" in ran:
        out += recovery.gcp_checks(truth, results / "gcp")
    if "to" in ran:
        folders = {s: (results / s if s in ran else None) for s in ("to", "vo", "do")}
        out += recovery.treatment_checks(truth, folders["to"], folders["vo"], folders["do"], PREPROCESSED_TRIAL)
    return out


def _text(checks: list[recovery.Check], times: dict[str, float], total: float, folder: Path) -> str:
    lines = [recovery.format_checks(checks), ""]
    for stage, (good, count) in recovery.summary(checks).items():
        lines.append(f"{stage}: {good} of {count} judged quantities within tolerance")
    if "do" in times:
        lines.append(f"DO: gait predicted with {', '.join(PLANTARFLEXORS)} at {100 * PLANTARFLEXOR_STRENGTH:.0f}% "
                     "strength (rows 'change vs VO' above)")
    lines.append("stage times (s): " + ", ".join(f"{k} {v:.1f}" for k, v in times.items()))
    lines.append(f"total {total:.1f} s; results and report.html in {folder / 'results'}")
    return "\n".join(lines)


def run_example(folder: str | os.PathLike[str] = "nmsm_example", *, until: str | None = None, rebuild: bool = False,
                log=print) -> ExampleOutcome:
    """Run the example (module docstring) up to stage ``until`` (default: every stage)."""
    from nmsm.errors import InputError
    from nmsm.examples.subject import make_subject, subject_in
    from nmsm.examples.subject_settings import write_example_pipeline
    from nmsm.examples.subject_truth import N_SYNERGIES
    from nmsm.tools.pipeline.runner import DISABLED, NOT_SELECTED, run_pipeline_file

    if until is not None and until not in STAGES:
        raise InputError(f"no example stage '{until}'", element="nmsm example STAGE",
                         expected="one of " + ", ".join(STAGES))
    began = time.perf_counter()
    folder = Path(folder)
    if rebuild and folder.exists():
        shutil.rmtree(folder)
    subject = subject_in(folder)
    if subject is None:
        subject = make_subject(folder, log=log)
    stages = STAGES if until is None else STAGES[: STAGES.index(until) + 1]
    pipeline = write_example_pipeline(subject, folder, n_synergies=N_SYNERGIES, stages=stages)
    run = run_pipeline_file(pipeline, log=log)
    ran = {s.name for s in run.stages if s.status not in (DISABLED, NOT_SELECTED)}
    times = {s.name: s.wall_time for s in run.stages if s.name in ran}
    checks = _checks(folder, run.results_directory, ran)
    total = time.perf_counter() - began
    text = _text(checks, times, total, folder)
    from nmsm.report.html import write_report

    write_report(run.results_directory, checks=checks, title="nmsm example: synthetic subject", log=None)
    return ExampleOutcome(folder, run.results_directory, tuple(checks), text, total, times)

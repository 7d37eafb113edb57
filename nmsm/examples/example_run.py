"""``nmsm example [STAGE]``: the synthetic subject from lab data to treatment, with answers.

1. Generate the subject (:func:`nmsm.examples.subject.make_subject`) into
   ``<folder>/subject`` and ``<folder>/truth``, unless it is already there;
2. write ``<folder>/pipeline.xml`` (:mod:`nmsm.examples.subject_settings`) with the stages
   up to ``until`` and run it (:mod:`nmsm.tools.pipeline.runner`: finished stages are kept,
   so running again only redoes what changed);
3. compare what each stage found with the truth (:mod:`nmsm.examples.subject_recovery`)
   and write ``<folder>/results/report.html`` (:mod:`nmsm.report`) with the comparison.

Nothing outside the installed package is needed (no OpenSim, no data files).

The folder: a folder the example creates (absent or empty when it starts) gets a marker file
(:data:`MARKER`); ``rebuild`` deletes the folder only when it holds that marker, so a
user's own folder (or an example folder of an nmsm older than the marker) is never deleted:
:func:`prepare_example_folder` refuses with an :class:`~nmsm.errors.InputError` instead.
"""

from __future__ import annotations

import os
import shutil
import time
from pathlib import Path

import attrs

from nmsm.examples import subject_recovery as recovery
from nmsm.errors import InputError
from nmsm.examples.subject_settings import PLANTARFLEXOR_STRENGTH, PLANTARFLEXORS, PREPROCESSED_TRIAL, STAGES

#: file written into a folder the example creates; ``rebuild`` deletes only folders holding it
MARKER = ".nmsm_example"
MARKER_TEXT = ("This folder was created by `nmsm example`; `nmsm example --rebuild` deletes it and everything in "
               "it.\n")
#: entries of a refused folder named in the error
NAMED_ENTRIES = 4


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


def _entries(folder: Path) -> str:
    """A few names in ``folder`` (sorted), then 'and N more'."""
    names = sorted(p.name + ("/" if p.is_dir() else "") for p in folder.iterdir())
    text = ", ".join(names[:NAMED_ENTRIES])
    return text + (f" and {len(names) - NAMED_ENTRIES} more" if len(names) > NAMED_ENTRIES else "")


def _check_is_folder(folder: Path) -> None:
    """:class:`InputError` when ``folder`` or one of its parents exists but is not a folder."""
    for path in (folder, *folder.parents):
        if path.exists() or path.is_symlink():
            if not path.is_dir():
                what = "is a file" if path == folder else f"lies in {path}, which is a file"
                raise InputError(f"{what}, not a folder", file=folder, element="--folder",
                                 expected="a folder for the example's subject and results (created when absent)")
            return


def _looks_like_old_example(folder: Path) -> bool:
    return (folder / "subject").is_dir() and (folder / "truth").is_dir()


def _check_deletable(folder: Path) -> None:
    """:class:`InputError` unless ``folder`` is one the example created (it holds :data:`MARKER`)
    and deleting it leaves the current working folder alone."""
    if folder.is_symlink():
        raise InputError("--rebuild does not delete a symbolic link", file=folder, element="--folder",
                         expected="a folder created by `nmsm example`")
    if (folder / MARKER).is_file():
        here = Path.cwd().resolve()
        target = folder.resolve()
        if target == here or target in here.parents:
            raise InputError("--rebuild would delete the current working folder (or a folder holding it)", file=folder,
                             element="--folder", expected="an example folder other than the one you are in")
        return
    if _looks_like_old_example(folder):
        raise InputError(f"--rebuild refused: no {MARKER} marker file, so this looks like an example folder written "
                         f"by an older nmsm (it holds {_entries(folder)}); delete it by hand, then run the example "
                         "again", file=folder, element="--folder",
                         expected=f"a folder the example created (holding {MARKER})")
    raise InputError(f"--rebuild refused: not a folder created by `nmsm example` (no {MARKER} marker file); it holds "
                     f"{_entries(folder)}", file=folder, element="--folder",
                     expected="another --folder, or this folder deleted by hand if its contents may go")


def prepare_example_folder(folder: str | os.PathLike[str], *, rebuild: bool = False) -> Path:
    """Make ``folder`` ready for the example and return it.

    ``rebuild``: delete it first, only when the example created it (module docstring);
    otherwise :class:`InputError` naming the folder and a few of its entries. A folder that is
    absent or empty is created and marked (:data:`MARKER`); a folder with other contents is
    used as it is, unmarked. A file given as the folder: :class:`InputError`.
    """
    folder = Path(folder)
    _check_is_folder(folder)
    if rebuild and folder.exists() and any(folder.iterdir()):
        _check_deletable(folder)
        shutil.rmtree(folder)
    if not folder.exists() or not any(folder.iterdir()):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / MARKER).write_text(MARKER_TEXT, encoding="utf-8")
    return folder


def run_example(folder: str | os.PathLike[str] = "nmsm_example", *, until: str | None = None, rebuild: bool = False,
                log=print) -> ExampleOutcome:
    """Run the example (module docstring) up to stage ``until`` (default: every stage) in ``folder``
    (see :func:`prepare_example_folder` for ``rebuild``)."""
    from nmsm.examples.subject import make_subject, subject_in
    from nmsm.examples.subject_settings import write_example_pipeline
    from nmsm.examples.subject_truth import N_SYNERGIES
    from nmsm.tools.pipeline.runner import DISABLED, NOT_SELECTED, run_pipeline_file

    if until is not None and until not in STAGES:
        raise InputError(f"no example stage '{until}'", element="nmsm example STAGE",
                         expected="one of " + ", ".join(STAGES))
    began = time.perf_counter()
    folder = prepare_example_folder(folder, rebuild=rebuild)
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

"""The output folder of ``nmsm preprocess``: never an input's folder, never a mix of runs, all or nothing.

* :func:`check_not_input_folder`: the output folder may not be the folder of an input file
  (nor a muscle-analysis folder given as input): the trials would be written among the raw
  data.
* :func:`earlier_trial_files` / :func:`refuse_earlier_trials`: files of a trial this run
  writes that are already in ``IKData``, ``IDData``, ``EMGData``, ``GRFData`` or
  ``MAData/<trial>/`` and that this run would not rewrite are refused with an
  :class:`InputError` listing them; otherwise the tools reading the folder would combine
  one run's IK with another run's ID or muscle analysis (of another time window). Files of
  the trial are those :func:`nmsm.io.trials.contains_trial` finds.

Staging (all or nothing) is :meth:`nmsm.core.results.ResultsDirectory.task`'s, as for every tool.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.layout import TRIAL_FOLDERS  # the trial folders a run writes (MAData: <trial>/ folders)
from nmsm.io.trials import contains_trial

def check_not_input_folder(output: Path, inputs: Mapping[str, Path | None],
                           folders: Mapping[str, Path | None] | None = None) -> None:
    """:class:`InputError` when ``output`` is the folder holding one of ``inputs`` (option ->
    file) or is one of ``folders`` (option -> input folder)."""
    target = output.resolve()
    for option, path in inputs.items():
        if path is not None and Path(path).resolve().parent == target:
            raise InputError(f"the output folder {output} holds the input {path} ({option}): the trials would be "
                             "written among the input data", element="--output",
                             expected="an output folder apart from the inputs' folders (e.g. preprocessed)")
    for option, path in (folders or {}).items():
        if path is not None and Path(path).resolve() == target:
            raise InputError(f"the output folder {output} is the input folder {path} ({option})", element="--output",
                             expected="an output folder apart from the inputs' folders (e.g. preprocessed)")


def earlier_trial_files(output: Path, names: Iterable[str]) -> list[str]:
    """Files (paths relative to ``output``, ``/``-separated, sorted) of trials ``names`` in
    the trial folders of ``output``."""
    found: set[str] = set()
    for folder in TRIAL_FOLDERS:
        directory = output / folder
        if not directory.is_dir():
            continue
        for entry in directory.iterdir():
            if entry.name.startswith(".") or not any(contains_trial(entry.name, name) for name in names):
                continue
            if entry.is_dir():
                found.update(p.relative_to(output).as_posix() for p in entry.rglob("*") if p.is_file())
            elif entry.is_file():
                found.add(entry.relative_to(output).as_posix())
    return sorted(found)


def refuse_earlier_trials(output: Path, names: Collection[str], written: Collection[str],
                          open_folders: Collection[str] = ()) -> None:
    """:class:`InputError` listing the files of trials ``names`` already in ``output`` that
    this run would not rewrite (not in ``written``, paths relative to ``output``). Files in
    ``open_folders`` (trial folders whose files this run does not know yet, e.g. a muscle
    analysis still to compute) are not judged."""
    rewritten = set(written)
    stale = [f for f in earlier_trial_files(output, names)
             if f not in rewritten and f.split("/", 1)[0] not in set(open_folders)]
    if not stale:
        return
    shown = ", ".join(stale[:8]) + (f" and {len(stale) - 8} more" if len(stale) > 8 else "")
    raise InputError(f"the output folder {output} already holds files of trial(s) {', '.join(sorted(names))} that "
                     f"this run would not rewrite: {shown}; the tools would combine them with this run's files (another run, "
                     "maybe another time window)", file=output, element="--output",
                     expected="a new output folder, or one without those files (move or remove them first)")


__all__ = ["TRIAL_FOLDERS", "check_not_input_folder", "earlier_trial_files", "refuse_earlier_trials"]

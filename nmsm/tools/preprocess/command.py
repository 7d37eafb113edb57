"""The one checked path of preprocessing: everything checked first, then :func:`.run.process`
into a staging folder, moved into place only when the whole run succeeded. ``nmsm
preprocess``, :func:`preprocess` (Python callers) and the pipeline's ``<DataPreprocessingTool>`` stage
(several recordings into one folder) all run :func:`run_checked`.

Before anything is processed (:func:`check_request`):

1. the arguments (time pairs finite and increasing, ``--rows`` >= 2, padding >= 0, a plain
   ``--prefix``, one way to give each input, a model where one is needed);
2. the output folder: not the folder of an input file, and no files of the trials this run
   writes that it would not rewrite (:mod:`.output`);
3. every input file's time range against the time pairs (EMG: widened by the padding;
   markers and the IK settings' ``<time_range>`` for a computed IK; every muscle-analysis
   file), naming the file that falls short.

With several requests (recordings) every one is checked before any is processed, and their
trial names must differ. Then :func:`.run.process` writes into a hidden staging folder
inside the output folder; the earlier-files check is repeated on the files actually made (a
computed muscle analysis' file names are known only then) and the files are moved into the
output folder. An error at any point leaves the output folder as it was
(:meth:`nmsm.core.results.ResultsDirectory.task`). An error of a request read from a
settings file (``settings_file``) names that file and the element for the option
(``elements``) unless it names a data file.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import attrs
import numpy as np

from nmsm.core.results import ResultsDirectory
from nmsm.errors import InputError
from nmsm.tools.preprocess import analyses
from nmsm.tools.preprocess.output import check_not_input_folder, refuse_earlier_trials
from nmsm.tools.preprocess.run import PreprocessRequest, process, select_channels
from nmsm.tools.preprocess.signals import check_covers
from nmsm.tools.preprocess.tables import read_table
from nmsm.tools.preprocess.trials import check_time_pairs, emg_windows, ground_reaction_nan, ma_files

#: pairs of options that give the same input two ways
_EITHER = (("raw_emg", "processed_emg", "--raw-emg", "--emg"), ("ik", "markers", "--ik", "--markers"),
           ("inverse_dynamics", "external_loads", "--id", "--external-loads"),
           ("muscle_analysis", "compute_muscle_analysis", "--muscle-analysis", "--compute-muscle-analysis"))


def trial_names(request: PreprocessRequest) -> list[str]:
    """The trial names after checking the arguments (no file read): :class:`InputError`
    naming the option otherwise."""
    check_time_pairs(request.time_pairs, element="--time-pair")
    if not request.prefix or any(c in request.prefix for c in "/\\") or request.prefix in (".", ".."):
        raise InputError(f"prefix '{request.prefix}'", element="--prefix",
                         expected="a plain file name part (e.g. gait)")
    if request.rows < 2:
        raise InputError(f"{request.rows} rows per trial", element="--rows", expected="2 or more (101 by default)")
    if not (math.isfinite(request.emg_padding_time) and request.emg_padding_time >= 0):
        raise InputError(f"EMG padding time {request.emg_padding_time} s", element="--emg-padding-time",
                         expected="a time >= 0 s (0.2 by default)")
    if request.cutoff is not None and not request.cutoff > 0:
        raise InputError(f"cut-off {request.cutoff} Hz", element="--cutoff", expected="a frequency > 0 Hz (or none)")
    if request.engine not in analyses.ENGINES:
        raise InputError(f"unknown engine '{request.engine}'", element="--engine",
                         expected=" or ".join(analyses.ENGINES))
    for first, second, first_option, second_option in _EITHER:
        if getattr(request, first) and getattr(request, second):
            raise InputError(f"both {first_option} and {second_option} given",
                             element=f"{first_option}/{second_option}", expected="one of them")
    needs_model = request.markers is not None or request.compute_muscle_analysis or request.external_loads is not None
    if needs_model and request.model is None:
        raise InputError("a model is needed to compute IK, ID or muscle analysis", element="--model",
                         expected="the subject's .osim model")
    has_motion = request.ik is not None or request.markers is not None
    if request.external_loads is not None and not has_motion:
        raise InputError("inverse dynamics needs a motion", element="--ik/--markers", expected="an IK file or markers")
    if request.compute_muscle_analysis and not has_motion:
        raise InputError("muscle analysis needs a motion", element="--ik/--markers", expected="an IK file or markers")
    if request.names:
        if len(request.names) != len(request.time_pairs) or any(not n or any(c in n for c in "/\\")
                                                                 for n in request.names):
            raise InputError(f"trial names {', '.join(request.names)} for {len(request.time_pairs)} time pair(s)",
                             element="--prefix", expected="one plain file name per time pair")
        return list(request.names)
    return [f"{request.prefix}_{k}" for k in range(1, len(request.time_pairs) + 1)]


def check_input_times(request: PreprocessRequest) -> None:
    """Every input file read and checked to cover the time pairs (EMG: widened by the
    padding), naming the file that falls short; markers (and the IK settings' time range)
    for a computed IK. Nothing is processed."""
    pairs = request.time_pairs
    for path, what, nan in ((request.ik, "IK", None), (request.inverse_dynamics, "ID", None),
                            (request.grf, "GRF", ground_reaction_nan)):
        if path is not None:
            check_covers(read_table(path, allow_nan=nan).time, pairs, what=what, file=path)
    emg = request.raw_emg if request.raw_emg is not None else request.processed_emg
    if emg is not None:
        table = select_channels(read_table(emg), request.emg_channels)
        check_covers(table.time, emg_windows(pairs, request.rows, request.emg_padding_time,
                                             per_window=request.emg_padding_per_window), what="EMG", file=emg)
    if request.markers is not None:
        _check_marker_times(request)
    if request.muscle_analysis is not None:
        for key, path in ma_files(Path(request.muscle_analysis)).items():
            check_covers(read_table(path).time, pairs, what=f"MuscleAnalysis {key}", file=path)


def _check_marker_times(request: PreprocessRequest) -> None:
    from nmsm.io.trc import read_trc
    from nmsm.tools.jmp.ik_settings import read_ik_settings

    time = read_trc(request.markers).time
    check_covers(time, request.time_pairs, what="markers (for IK)", file=request.markers)
    settings = read_ik_settings(request.ik_settings) if request.ik_settings is not None else None
    if settings is not None and settings.time_range is not None:
        start, end = settings.time_range
        check_covers(np.array([max(start, time[0]), min(end, time[-1])]), request.time_pairs,
                     what="IK (<time_range> of the IK settings, within the markers)", file=request.ik_settings)


def planned_files(request: PreprocessRequest, names: Sequence[str]) -> tuple[list[str], list[str]]:
    """Trial files this run will write (relative to the output folder) and the trial
    folders whose files are known only after processing (a muscle analysis to compute)."""
    planned, open_folders = [], []
    for folder, given in (("IKData", request.ik is not None or request.markers is not None),
                          ("IDData", request.inverse_dynamics is not None or request.external_loads is not None),
                          ("GRFData", request.grf is not None),
                          ("EMGData", request.raw_emg is not None or request.processed_emg is not None)):
        if given:
            planned += [f"{folder}/{name}.sto" for name in names]
    if request.muscle_analysis is not None:
        keys = set(ma_files(Path(request.muscle_analysis))) | {"Velocity"}
        planned += [f"MAData/{name}/{name}_{key}.sto" for name in names for key in sorted(keys)]
    elif request.compute_muscle_analysis:
        open_folders.append("MAData")
    return planned, open_folders


def check_request(request: PreprocessRequest) -> list[str]:
    """Steps 1-3 of the module docstring; the trial names."""
    out = Path(request.output)
    names = trial_names(request)
    def named(options: dict[str, Path | None]) -> dict[str, Path | None]:  # as the user gave them
        return {request.elements.get(option, option): path for option, path in options.items()}

    check_not_input_folder(out, named({"--model": request.model, "--raw-emg": request.raw_emg,
                                       "--emg": request.processed_emg, "--markers": request.markers,
                                       "--ik-settings": request.ik_settings, "--ik": request.ik,
                                       "--id": request.inverse_dynamics, "--external-loads": request.external_loads,
                                       "--grf": request.grf, "--muscle-analysis": request.muscle_analysis}),
                           named({"--muscle-analysis": request.muscle_analysis}))
    refuse_earlier_trials(out, names, *planned_files(request, names))
    check_input_times(request)
    return names


@contextmanager
def _named(request: PreprocessRequest) -> Iterator[None]:
    """Errors without a file, or about the output folder (whose messages name it), name the
    request's settings file and the element for the option."""
    try:
        yield
    except InputError as exc:
        if request.settings_file is not None and (exc.file is None or exc.element == "--output"):
            exc.file = str(request.settings_file)
            exc.element = request.elements.get(exc.element or "", exc.element)
            exc.args = (exc._compose(),)
        raise


def run_checked(requests: PreprocessRequest | Sequence[PreprocessRequest], *,
                keep_intermediate: bool = True) -> list[str]:
    """Check every request (:func:`check_request`), then process them staged into their
    common output folder (module docstring); returns the trial names. ``keep_intermediate``:
    keep ``intermediate/`` (with several requests, one subfolder named after each request's first trial)."""
    requests = [requests] if isinstance(requests, PreprocessRequest) else list(requests)
    if not requests:
        raise ValueError("no preprocessing request")
    out = Path(requests[0].output)
    names: list[str] = []
    for request in requests:
        with _named(request):
            if Path(request.output).resolve() != out.resolve():
                raise InputError(f"output folder {request.output} differs from {out}", element="--output",
                                 expected="one output folder for every recording")
            made = check_request(request)
            twice = sorted(set(made) & set(names))
            if twice:
                raise InputError(f"trial name(s) {', '.join(twice)} made twice", element="--prefix",
                                 expected="recordings whose trial names differ")
        names += made
    with ResultsDirectory(out).task("preprocess") as stage:
        for request in requests:
            work = stage / "intermediate" / (trial_names(request)[0] if len(requests) > 1 else "")
            with _named(request):
                process(attrs.evolve(request, output=stage), work)
        if not keep_intermediate:
            shutil.rmtree(stage / "intermediate", ignore_errors=True)
        written = sorted(p.relative_to(stage).as_posix() for p in stage.rglob("*") if p.is_file())
        refuse_earlier_trials(out, names, [f for f in written if not f.startswith("intermediate/")])
    return names


__all__ = ["check_input_times", "check_request", "planned_files", "run_checked", "trial_names"]


def preprocess(request: PreprocessRequest) -> list[str]:
    """Check ``request``, then run the steps of :mod:`nmsm.tools.preprocess.run` staged (nothing
    is written on bad input, nothing half-written is left on an error); returns the trial names."""
    return run_checked([request])

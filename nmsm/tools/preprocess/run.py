"""Preprocessing of one recording into the personalization layout (what ``nmsm preprocess`` runs).

Steps (docs/preprocess.md), each optional:

1. raw EMG -> processed EMG (:func:`nmsm.tools.preprocess.emg.process_emg`);
2. IK from markers, ID from IK (+ external loads), muscle analysis from IK, through nmsm's
   model core or OpenSim (``engine``), unless the files are given;
3. muscle-tendon velocity from lengths when the analysis folder has none (made in a copy
   of the folder under ``intermediate/``: inputs are never written);
4. split everything into trials (:func:`nmsm.tools.preprocess.trials.split_into_trials`).

Intermediate files go to ``<output>/intermediate/``; trials to ``<output>/{IKData, IDData,
EMGData, GRFData, MAData}``.

:func:`nmsm.tools.preprocess.command.preprocess` is the checked path every entry point takes
(``nmsm preprocess``, the pipeline's ``<DataPreprocessingTool>`` stage and Python callers):
the request is checked first, then processed into a staging folder that is moved into place
only when everything succeeded (:func:`nmsm.tools.preprocess.command.run_checked`).
:func:`process` is the unchecked processing step alone, writing straight into ``request.output``.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Mapping, Sequence
from pathlib import Path

import attrs

from nmsm.errors import InputError
from nmsm.io.storage import Table, write_storage
from nmsm.tools.preprocess import analyses
from nmsm.tools.preprocess.emg import process_emg
from nmsm.tools.preprocess.tables import read_table
from nmsm.tools.preprocess.trials import EMG_PADDING_SECONDS, TrialSources, split_into_trials
from nmsm.tools.preprocess.velocity import create_velocity_file


@attrs.frozen
class EmgOptions:
    """Raw-EMG processing: Butterworth order, cut-offs (Hz), demean mode (:mod:`.emg`).

    The original's defaults are 40 Hz and 10 Hz; its tutorial runs ``low_pass_cutoff =
    3.5 / 1.1`` (3.5 cycles over the 1.1 s gait trial).
    """

    filter_order: int = 4
    high_pass_cutoff: float = 40.0
    low_pass_cutoff: float = 10.0
    demean: str = "frame"


@attrs.frozen
class PreprocessRequest:
    """What to preprocess. Paths may be None (the step is skipped or computed when possible).

    ``emg_channels``: the EMG columns to keep (e.g. the model's muscle-group names); each must
    exist in the EMG file. Empty: all columns.
    """

    time_pairs: tuple[tuple[float, float], ...]
    output: Path
    model: Path | None = None
    prefix: str = "trial"
    rows: int = 101
    cutoff: float | None = 6.0
    engine: str = "nmsm"
    raw_emg: Path | None = None
    processed_emg: Path | None = None
    emg: EmgOptions = EmgOptions()
    emg_channels: tuple[str, ...] = ()
    emg_padding_time: float = EMG_PADDING_SECONDS
    markers: Path | None = None
    ik_settings: Path | None = None
    ik: Path | None = None
    inverse_dynamics: Path | None = None
    external_loads: Path | None = None
    grf: Path | None = None
    muscle_analysis: Path | None = None
    compute_muscle_analysis: bool = False
    muscles: tuple[str, ...] = ()
    coordinates: tuple[str, ...] = ()
    filter_order: int = 4  #: Butterworth order of the IK, ID and muscle-analysis low-pass
    ik_radians: bool = True  #: write rotational IK in radians (False: keep the input's unit)
    clip_emg: bool = False  #: set the EMG spline's undershoots below 0 to 0
    emg_padding_per_window: bool = False  #: each time pair its own EMG padding (else the shortest's)
    names: tuple[str, ...] = ()  #: the trials' names, one per time pair (default ``<prefix>_<k>``)
    settings_file: Path | None = None  #: settings file the request was read from (named in errors)
    #: command-line option (``--rows``) -> the settings element that gave it, for errors
    elements: Mapping[str, str] = attrs.field(factory=dict)


def process_emg_table(table: Table, options: EmgOptions = EmgOptions()) -> Table:
    """``processEmg`` on every column of a raw EMG table: the processed table (same times)."""
    try:
        processed = process_emg(table.time, table.data, filter_order=options.filter_order,
                                high_pass_cutoff=options.high_pass_cutoff, low_pass_cutoff=options.low_pass_cutoff,
                                demean=options.demean, labels=table.labels)
    except InputError as exc:  # name the raw EMG file
        if exc.file is not None or table.source is None:
            raise
        raise InputError(exc.detail, file=table.source, line=exc.line, element=exc.element,
                         expected=exc.expected) from exc
    return Table(time=table.time, labels=table.labels, data=processed, name="processedEmg", source=table.source)


def select_channels(table: Table, channels: Sequence[str]) -> Table:
    """The EMG columns ``channels`` (in that order); a missing one is an error naming it."""
    if not channels:
        return table
    missing = [c for c in channels if c not in table.labels]
    if missing:
        raise InputError(f"EMG column(s) {', '.join(missing)} not in the EMG file", file=table.source,
                         element="EMG columns", expected=f"one of {', '.join(table.labels)}")
    return attrs.evolve(table, labels=tuple(channels), data=table.columns(list(channels)))


def process_raw_emg_file(raw: str | os.PathLike[str], output: str | os.PathLike[str],
                         options: EmgOptions = EmgOptions(), channels: Sequence[str] = ()) -> Path:
    """``processRawEmgFile``: filter, rectify, normalize every column (or ``channels``) of a raw EMG file."""
    table = select_channels(read_table(raw), channels)
    out = Path(output)
    out.parent.mkdir(parents=True, exist_ok=True)
    return write_storage(out, process_emg_table(table, options))


def _rotational(model_file: Path | None) -> tuple[str, ...]:
    if model_file is None:
        return ()
    from nmsm.model import load_model

    model = load_model(model_file)
    return tuple(c.name for c in model.coordinates if c.motion_type == "rotational")


def _with_velocity(folder: Path, work: Path) -> Path:
    """A muscle-analysis folder with a ``*_Velocity.sto``: ``folder`` itself, or a copy in
    ``work`` with the velocity made from the lengths (the user's folder is not written)."""
    lengths = sorted(folder.glob("*_Length.sto"))
    if not lengths or sorted(folder.glob("*_Velocity.sto")):
        return folder
    if folder.resolve() != work.resolve():
        work.mkdir(parents=True, exist_ok=True)
        for path in folder.iterdir():
            if path.is_file() and path.suffix.lower() in (".sto", ".mot"):
                shutil.copyfile(path, work / path.name)
    create_velocity_file(work / lengths[0].name)
    return work


def process(request: PreprocessRequest, work: Path | None = None) -> list[str]:
    """The steps of the module docstring, unchecked, into ``request.output`` (intermediate
    files into ``work``, default ``<output>/intermediate``); returns the trial names. Use
    :func:`preprocess`, which checks the request first and stages the files."""
    out = Path(request.output)
    work = out / "intermediate" if work is None else work
    needs_model = request.markers is not None or request.compute_muscle_analysis or (
        request.inverse_dynamics is None and request.external_loads is not None)
    if needs_model and request.model is None:
        raise InputError("a model is needed to compute IK, ID or muscle analysis", element="--model",
                         expected="the subject's .osim model")
    emg = request.processed_emg
    if request.raw_emg is not None:
        emg = process_raw_emg_file(request.raw_emg, work / "processedEmg.sto", request.emg, request.emg_channels)
    elif emg is not None and request.emg_channels:
        emg = select_channels(read_table(emg), request.emg_channels)
    ik = request.ik
    if ik is None and request.markers is not None:
        ik = analyses.inverse_kinematics(request.model, request.markers, work / "ik.mot", engine=request.engine,
                                         ik_settings=request.ik_settings)
    inverse_dynamics = request.inverse_dynamics
    if inverse_dynamics is None and request.external_loads is not None:
        if ik is None:
            raise InputError("inverse dynamics needs a motion", element="--ik/--markers", expected="an IK file or markers")
        inverse_dynamics = analyses.inverse_dynamics(request.model, ik, work / "id.sto", engine=request.engine,
                                                     external_loads=request.external_loads, lowpass_hz=request.cutoff)
    ma = request.muscle_analysis
    if ma is None and request.compute_muscle_analysis:
        if ik is None:
            raise InputError("muscle analysis needs a motion", element="--ik/--markers", expected="an IK file or markers")
        ma = analyses.muscle_analysis(request.model, ik, work / "MuscleAnalysis", engine=request.engine,
                                      muscles=request.muscles or None, coordinates=request.coordinates or None,
                                      name=request.prefix)
    if ma is not None:
        ma = _with_velocity(Path(ma), work / "MuscleAnalysis")
    sources = TrialSources(ik=ik, inverse_dynamics=inverse_dynamics, grf=request.grf, emg=emg,
                           muscle_analysis=ma, rotational=_rotational(request.model) if ik is not None else ())
    return split_into_trials(request.time_pairs, sources, out, prefix=request.prefix, names=request.names or None,
                             rows=request.rows,
                             cutoff=request.cutoff, filter_order=request.filter_order,
                             emg_padding_time=request.emg_padding_time,
                             emg_padding_per_window=request.emg_padding_per_window, ik_radians=request.ik_radians,
                             clip_emg=request.clip_emg)


def parse_time_pairs(texts: Sequence[str]) -> tuple[tuple[float, float], ...]:
    """``["0.5 1.6", "2.1 3.2"]`` -> ``((0.5, 1.6), (2.1, 3.2))``."""
    pairs = []
    for text in texts:
        parts = text.replace(",", " ").split()
        try:
            values = [float(p) for p in parts]
        except ValueError:
            raise InputError(f"time pair '{text}' is not two numbers", element="--time-pair",
                             expected="'START END' in seconds") from None
        if len(values) != 2:
            raise InputError(f"time pair '{text}' has {len(values)} numbers", element="--time-pair",
                             expected="'START END' in seconds")
        pairs.append((values[0], values[1]))
    return tuple(pairs)


__all__ = ["EmgOptions", "PreprocessRequest", "parse_time_pairs", "preprocess", "process", "process_emg_table",
           "process_raw_emg_file", "select_channels"]

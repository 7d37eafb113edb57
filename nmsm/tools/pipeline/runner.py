"""Running a pipeline file: ``nmsm pipeline PIPELINE.xml`` / :func:`nmsm.run_pipeline`.

Before anything runs, every selected stage's settings are validated as its tool will read
them (:mod:`nmsm.tools.pipeline.validation`: elements, values, term types, solver settings;
errors at the user's settings file and line), so a typo stops the run before any stage runs
and before any results are emptied. Then, for each enabled stage, in order:

1. read its settings (file or embedded; old schemas upgraded), rewire its inputs to the
   artifacts available so far (:mod:`nmsm.tools.pipeline.wiring`), point its
   ``results_directory`` at ``<results>/<stage name>/`` and make every other path absolute;
2. hash its inputs (settings plus the contents of every file and folder they name, and
   nmsm's own code);
3. if ``pipeline_state.json`` records that digest and the recorded outputs are unchanged,
   skip it ("up to date"); otherwise write ``<results>/<stage name>.xml`` (a settings file
   ``nmsm run`` accepts), empty the stage's folder (it gets the runner's marker, see
   :mod:`nmsm.tools.pipeline.state`), run the tool on that file, find its outputs and record
   the stage. An error the tool reports at a line of that file is re-pointed at the user's
   settings file and the element's line there.

Before anything is written or deleted, :class:`~nmsm.errors.InputError` refuses a results
folder that is (or contains) the pipeline file's folder; an existing, non-empty stage folder
the runner did not create (not in ``pipeline_state.json``): the runner empties only folders
it wrote (with ``--rebuild``, also a folder holding the runner's marker: the state file may be
damaged); and a stage folder holding an input of a stage, the pipeline file, a settings file
or a starting input, unless it is that stage's own results read by a later stage (like a
wired output).

A stop (Ctrl-C, a failure) leaves the finished stages recorded: the next run skips them and
redoes the stopped one. A stage that runs again keeps its earlier results in a hidden
``.<stage>.earlier`` folder until it finishes; if it fails or is stopped without writing
anything, the earlier results (and settings copy) are put back, still recorded with their
old inputs, so the next run redoes the stage; if it wrote a diagnosis (a solver failure's
last iterate), that stays and the earlier results move into its ``superseded/``. Results tree::

    <results_directory>/
        pipeline.xml              copy of the pipeline file
        pipeline_state.json       records of finished stages (:mod:`nmsm.tools.pipeline.state`)
        pipeline_summary.txt      what ran, what was up to date, times, outputs
        <stage>.xml               each stage's settings, inputs wired (``nmsm run <stage>.xml``)
        <stage>/                  each stage's results
"""

from __future__ import annotations

import datetime
import inspect
import os
import shutil
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

import attrs
from lxml import etree

from nmsm.errors import InputError, NmsmError
from nmsm.io.xml_input import xml_parser
from nmsm.tools.pipeline.artifacts import INPUT_ELEMENTS, Artifacts
from nmsm.tools.pipeline.hashing import DigestCache, code_digest
from nmsm.tools.pipeline.pipeline_file import PipelineSpec, StageSpec, read_pipeline
from nmsm.tools.pipeline.plan import check_inputs, check_order
from nmsm.tools.pipeline.stage_settings import StageSettings
from nmsm.tools.pipeline.state import MARKER, VERSION, PipelineState, StageRecord, has_marker, write_marker
from nmsm.tools.pipeline.validation import bind_stage, validate_stage
from nmsm.tools.pipeline.wiring import wire_stage

PIPELINE_COPY = "pipeline.xml"
SUMMARY_FILE = "pipeline_summary.txt"
#: names a stage may not take (files of the results tree)
RESERVED_NAMES = ("pipeline", "pipeline_state", "pipeline_summary", "report", "plots")

RAN, UP_TO_DATE, DISABLED, NOT_SELECTED = "ran", "up to date", "disabled", "not selected"


@attrs.frozen
class StageOutcome:
    """What happened to one stage in a run."""

    name: str
    kind: str
    label: str
    status: str
    wall_time: float  #: s (this run's, or the recorded one when up to date)
    settings_file: Path | None
    results_directory: Path | None
    outputs: dict[str, Path]
    wired: dict[str, str]
    result: Any = None  #: what the tool returned, when it ran


@attrs.frozen
class PipelineRun:
    """A finished pipeline run."""

    spec: PipelineSpec
    results_directory: Path
    stages: tuple[StageOutcome, ...]
    wall_time: float

    def stage(self, name: str) -> StageOutcome:
        for outcome in self.stages:
            if outcome.name == name:
                return outcome
        raise KeyError(name)

    def summary(self) -> str:
        lines = [f"pipeline '{self.spec.name}' ({self.spec.file}) -> {self.results_directory}"]
        for s in self.stages:
            timing = f"{s.wall_time:8.1f} s" if s.status in (RAN, UP_TO_DATE) else " " * 10
            lines.append(f"  {s.name:<14s} {s.kind:<10s} {s.status:<12s} {timing}")
            for element, source in s.wired.items():
                lines.append(f"      {element} <- {source}")
        lines.append(f"total {self.wall_time:.1f} s")
        return "\n".join(lines)


def _relative(path: Path, root: Path) -> str:
    return Path(os.path.relpath(path.resolve(), root.resolve())).as_posix()


def _stage_folder(results: Path, stage: StageSpec) -> Path:
    return results / stage.name


def prepare_stage(stage: StageSpec, artifacts: Artifacts, results: Path) -> tuple[StageSettings, dict[str, str]]:
    """The stage's settings wired to ``artifacts``, results in ``<results>/<name>``, paths absolute."""
    settings = stage.load_settings()
    wired = wire_stage(stage.kind, settings, artifacts, stage.keep)
    settings.set_path("results_directory", _stage_folder(results, stage))
    settings.absolutize()
    return settings, wired


def _outputs_intact(record: StageRecord, results: Path, cache: DigestCache) -> bool:
    for path in record.outputs.values():
        if not (results / path).exists():
            return False
    folder = results / record.results_directory
    return folder.is_dir() and cache.folder(folder) == record.output_digest


def _check_names(spec: PipelineSpec) -> None:
    for stage in spec.stages:
        if stage.name in RESERVED_NAMES:
            raise stage.error(f"the name '{stage.name}' is reserved for a file of the results tree",
                              element="<Stage name>", expected="another name")


def _selection(spec: PipelineSpec, only: Sequence[str] | None, until: str | None) -> set[str]:
    names = [s.name for s in spec.stages]
    for name in [*(only or ()), *([until] if until else [])]:
        if name not in names:
            raise InputError(f"no stage named '{name}'", file=spec.file, element="<Stage name>",
                             expected="one of " + ", ".join(names))
    selected = set(only) if only else set(names)
    if until:
        selected &= set(names[: names.index(until) + 1])
    return selected


def _check_stage_options(spec: PipelineSpec, stage_options: dict[str, dict[str, Any]]) -> None:
    """Refuse, before anything runs, ``stage_options`` for a stage the pipeline does not have
    or naming an option its tool's ``run_settings`` does not take."""
    stages = {s.name: s for s in spec.stages}
    for name, options in stage_options.items():
        if name not in stages:
            raise InputError(f"stage_options for '{name}', which is not a stage of the pipeline", file=spec.file,
                             expected="stage names: " + ", ".join(stages))
        parameters = inspect.signature(stages[name].kind.load_run()).parameters.values()
        if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in parameters):
            continue
        known = [p.name for p in parameters if p.kind is inspect.Parameter.KEYWORD_ONLY]
        unknown = [key for key in options if key not in known]
        if unknown:
            raise InputError(f"stage_options of stage '{name}': unknown option(s) {', '.join(unknown)}",
                             file=spec.file, expected="options of its tool: " + ", ".join(known))


def _with_accept_unconverged(spec: PipelineSpec, stage_options: dict[str, dict[str, Any]],
                             accept: bool) -> dict[str, dict[str, Any]]:
    """``stage_options`` with ``accept_unconverged=True`` for every optimizing stage when ``accept``
    and for the stages whose ``<accept_unconverged>`` is true."""
    from nmsm.tools.dispatch import SOLVING_TOOLS

    out = {name: dict(options) for name, options in stage_options.items()}
    for stage in spec.stages:
        if stage.accept_unconverged or (accept and stage.kind.tool_element in SOLVING_TOOLS):
            out.setdefault(stage.name, {})["accept_unconverged"] = True
    return out


def run_pipeline(spec: PipelineSpec, *, only: Sequence[str] | None = None, until: str | None = None,
                 rebuild: bool = False, force: Iterable[str] = (), check_only: bool = False,
                 log: Callable[[str], None] | None = print, stage_options: dict[str, dict[str, Any]] | None = None,
                 accept_unconverged: bool = False) -> PipelineRun:
    """Run a parsed pipeline (see module docstring).

    ``only``: run just these stages (the others must be up to date when a selected stage
    needs their outputs); ``until``: stop after this stage; ``rebuild``: redo every stage;
    ``force``: redo these stages; ``check_only``: validate (every selected stage's settings
    too), bind the terms of every stage that would run to its model and data
    (:func:`nmsm.tools.pipeline.validation.bind_stage`; a stage whose inputs an earlier stage
    of the run makes is bound when it runs, and the check says so) and report which stages
    would run and how they would be wired, without running or writing anything; every
    stage's errors are reported together. ``stage_options``: extra keyword arguments per stage
    name for its tool's ``run_settings``. ``accept_unconverged``: every optimizing stage
    writes its results although its solve did not converge (stamped as unconverged,
    :mod:`nmsm.core.unconverged`) instead of stopping the pipeline with its last iterate.
    """
    say = log or (lambda text: None)
    start = time.perf_counter()
    only = (only,) if isinstance(only, str) else only  # one stage name given as a string
    force = (force,) if isinstance(force, str) else force
    _check_names(spec)
    _check_stage_options(spec, stage_options or {})
    stage_options = _with_accept_unconverged(spec, stage_options or {}, accept_unconverged)
    check_order(spec)
    results = spec.results_directory
    _check_results_location(spec)
    enabled = [s for s in spec.stages if s.enabled]
    check_inputs(spec, {s.name: s.load_settings() for s in enabled})
    selected = _selection(spec, only, until)
    errors: list[tuple[str, InputError]] = []  # check_only: (stage, error), every stage's
    checked = validate_stages(spec, selected, quiet=not check_only, errors=errors if check_only else None)
    if check_only:
        say(f"settings checked: {', '.join(checked) or 'no stage selected'}")
    state = PipelineState.load(results, salvage=rebuild)
    protected = input_paths(spec, results)
    for stage in enabled:
        if stage.name in selected:
            try:
                _check_stage_folder(spec, stage, results, state, protected, trust_markers=rebuild)
            except InputError as exc:
                if not check_only:
                    raise
                errors.append((stage.name, exc))
    forced = set(force) | ({s.name for s in spec.stages} if rebuild else set())
    cache = DigestCache(exclude=[results])
    artifacts = Artifacts()
    unavailable: dict[str, str] = {}  # artifact -> stage that should have made it but did not run
    pending: set[str] = set()  # check_only: artifacts of stages that would run (wired, not made yet)
    stand_ins: set[Path] = set()  # check_only: where those artifacts are assumed
    for name, path in spec.inputs.items():
        artifacts.provide(name, path, "the pipeline inputs")
    if not check_only:
        results.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(spec.file, results / PIPELINE_COPY)
    outcomes: list[StageOutcome] = []
    for number, stage in enumerate(spec.stages, start=1):
        head = f"[{number}/{len(spec.stages)}] {stage.name} ({stage.kind.label})"
        if not stage.enabled:
            outcomes.append(StageOutcome(stage.name, stage.kind.code, stage.kind.label, DISABLED, 0.0, None, None,
                                         {}, {}))
            say(f"{head}: disabled")
            continue
        settings, wired = prepare_stage(stage, artifacts, results)
        accepted = "-accept-unconverged" if stage_options.get(stage.name, {}).get("accept_unconverged") else ""
        digest = settings.input_digest(cache, stage.kind.code, f"state-version-{VERSION}{accepted}", code_digest())
        record = state.records.get(stage.name)
        waits = any(a in pending for a in (*stage.kind.requires, *stage.kind.uses))
        current = (record is not None and record.input_digest == digest and record.kind == stage.kind.code
                   and stage.name not in forced and not waits and _outputs_intact(record, results, cache))
        settings_file = results / f"{stage.name}.xml"
        folder = _stage_folder(results, stage)
        if current:
            assert record is not None
            outputs = {k: results / v for k, v in record.outputs.items()}
            for artifact, path in outputs.items():
                artifacts.provide(artifact, path, f"stage '{stage.name}'")
                unavailable.pop(artifact, None)
            outcomes.append(StageOutcome(stage.name, stage.kind.code, stage.kind.label, UP_TO_DATE,
                                         record.wall_time, settings_file, folder, outputs, wired))
            say(f"{head}: up to date")
            continue
        if stage.name not in selected or check_only:
            status = NOT_SELECTED if stage.name not in selected else "would run"
            outcomes.append(StageOutcome(stage.name, stage.kind.code, stage.kind.label, status, 0.0,
                                         settings_file, folder, {}, wired))
            say(f"{head}: {status}")
            if status == "would run" and not any(name == stage.name for name, _ in errors):
                error = _bind_terms(stage, settings, wired, artifacts, stand_ins, say)
                if error is not None:
                    errors.append((stage.name, error))
            for artifact in stage.kind.produces:
                if stage.name in selected:  # --check: wired as in the run, made when the stage runs
                    artifacts.provide(artifact, _stand_in(results, stage, artifact), f"stage '{stage.name}'")
                    stand_ins.add(_stand_in(results, stage, artifact))
                    pending.add(artifact)
                    continue
                artifacts.items.pop(artifact, None)
                pending.discard(artifact)
                unavailable[artifact] = stage.name
            continue
        _require_available(stage, unavailable)
        say(f"{head}: running")
        _check_stage_folder(spec, stage, results, state, protected, trust_markers=rebuild)
        outcome = _run_stage(stage, settings, settings_file, folder, results, digest, state, cache, wired,
                             (stage_options or {}).get(stage.name, {}))
        for artifact, path in outcome.outputs.items():
            artifacts.provide(artifact, path, f"stage '{stage.name}'")
            unavailable.pop(artifact, None)
        outcomes.append(outcome)
        say(f"{head}: finished in {outcome.wall_time:.1f} s")
    if errors:
        order = [s.name for s in spec.stages]
        _raise_all([exc for _, exc in sorted(errors, key=lambda item: order.index(item[0]))])
    run = PipelineRun(spec, results, tuple(outcomes), time.perf_counter() - start)
    if not check_only:
        (results / SUMMARY_FILE).write_text(run.summary() + "\n", encoding="utf-8")
    return run


def _stand_in(results: Path, stage: StageSpec, artifact: str) -> Path:
    """Where an artifact of ``stage`` is assumed before the stage made it (never read)."""
    return _stage_folder(results, stage).resolve() / f".{artifact}"


def _bind_terms(stage: StageSpec, settings: StageSettings, wired: dict[str, str], artifacts: Artifacts,
                stand_ins: set[Path], say: Callable[[str], None]) -> InputError | None:
    """``--check``: bind the terms of a stage that would run (:func:`bind_stage`), or say why
    they are bound only when it runs; the binding error, naming the stage, else ``None``."""
    kind = stage.kind
    if not kind.has_terms and kind.bind is None:
        return None
    for key, source in wired.items():
        artifact = artifacts.get(source.split(" from ", 1)[0])
        if artifact is not None and artifact.path in stand_ins:
            say(f"      terms of stage '{stage.name}' are bound when it runs: its <{key.rsplit('/', 1)[-1]}> comes "
                f"from {artifact.source}")
            return None
    if kind.bind is None:
        say(f"      terms of stage '{stage.name}' are bound when it runs: {kind.label} binds them to the problem "
            "it builds from its data")
        return None
    try:
        bind_stage(stage, settings)
    except Exception as exc:  # noqa: BLE001 - every problem of binding is reported with the others
        if isinstance(exc, InputError):
            return InputError(f"stage '{stage.name}' ({kind.code}), binding its terms to its model and data: "
                              f"{exc.detail}", file=exc.file, line=exc.line, element=exc.element,
                              expected=exc.expected)
        what = str(exc) if isinstance(exc, NmsmError) else f"{type(exc).__name__}: {exc}"
        return InputError(f"stage '{stage.name}' ({kind.code}), binding its terms to its model and data: {what}",
                          file=stage.settings_file or stage.file)
    say(f"      terms of stage '{stage.name}' bound to its model and data")
    return None


def _raise_all(errors: Sequence[InputError]) -> None:
    """Raise the one error, or one listing them all."""
    if len(errors) == 1:
        raise errors[0]
    if errors:
        raise InputError(f"{len(errors)} errors in the pipeline's stages:\n  " + "\n  ".join(map(str, errors)))


def validate_stages(spec: PipelineSpec, selected: set[str], *, quiet: bool = True,
                    errors: list[tuple[str, InputError]] | None = None) -> list[str]:
    """Validate the settings of every enabled stage in ``selected`` as the runner will hand
    them to the tool (:mod:`nmsm.tools.pipeline.validation`), earlier stages' outputs wired
    as stand-ins; :class:`InputError` at the user's settings file and line of the first
    stage with an error (``errors``: append every stage's ``(stage, error)`` there instead of
    raising). Returns the names of the stages checked. Nothing is read from or written into
    the results tree."""
    results = spec.results_directory
    artifacts = Artifacts()
    for name, path in spec.inputs.items():
        artifacts.provide(name, path, "the pipeline inputs")
    checked: list[str] = []
    found: list[tuple[str, InputError]] = [] if errors is None else errors
    for stage in spec.stages:
        if not stage.enabled:
            continue
        if stage.name in selected:
            settings, _ = prepare_stage(stage, artifacts.copy(), results)
            try:
                validate_stage(stage, settings, quiet=quiet)
            except InputError as exc:
                if errors is None:
                    raise
                found.append((stage.name, exc))
            checked.append(stage.name)
        for artifact in stage.kind.produces:
            artifacts.provide(artifact, _stand_in(results, stage, artifact), f"stage '{stage.name}'")
    return checked


def _check_results_location(spec: PipelineSpec) -> None:
    """:class:`InputError` when the results folder is, or contains, the pipeline file's folder."""
    results, home = spec.results_directory.resolve(), spec.file.parent.resolve()
    if results == home or home.is_relative_to(results):
        where = "the pipeline file's own folder" if results == home else "a folder containing the pipeline file"
        raise InputError(f"the results folder {results} is {where}: the runner writes {PIPELINE_COPY}, "
                         "<stage>.xml and one folder per stage there, among the inputs", file=spec.file,
                         element="<results_directory>",
                         expected="a folder of its own, e.g. <results_directory>results</results_directory>")


def input_paths(spec: PipelineSpec, results: Path) -> dict[Path, tuple[str, int | None]]:
    """Every path a stage reads that the runner does not rewire (resolved), the pipeline
    file, the stage settings files and the starting inputs -> (what it is, index in
    ``spec.stages`` of the first stage reading it; ``None``: the pipeline's own input).
    Disabled stages count too (their settings as far as they can be read)."""
    paths: dict[Path, tuple[str, int | None]] = {spec.file.resolve(): ("the pipeline file", None)}
    for artifact, path in spec.inputs.items():
        paths[path.resolve()] = (f"<{INPUT_ELEMENTS[artifact]}> of the pipeline file", None)
    for stage in spec.stages:
        if stage.settings_file is not None:
            paths.setdefault(stage.settings_file.resolve(), (f"the settings file of stage '{stage.name}'", None))
    artifacts = Artifacts()
    for name, path in spec.inputs.items():
        artifacts.provide(name, path, "the pipeline inputs")
    produced: list[Path] = []  # stand-ins for the stages' outputs (files below a wired folder are outputs too)
    for index, stage in enumerate(spec.stages):
        try:
            settings = stage.load_settings()
        except InputError:
            if stage.enabled:
                raise
            continue
        wired = {f"{settings.tool_tag}/{key}" for key in wire_stage(stage.kind, settings, artifacts, stage.keep)}
        for field in settings.path_fields():
            if field.spec.output or field.key in wired:
                continue
            value = settings.resolve(field)
            if value is not None and not any(value.resolve().is_relative_to(p) for p in produced):
                paths.setdefault(value.resolve(), (f"<{field.spec.element}> of stage '{stage.name}'", index))
        for artifact in stage.kind.produces if stage.enabled else ():
            stand_in = _stand_in(results, stage, artifact)
            artifacts.provide(artifact, stand_in, f"stage '{stage.name}'")
            produced.append(stand_in)
    return paths


def _check_stage_folder(spec: PipelineSpec, stage: StageSpec, results: Path, state: PipelineState,
                        protected: dict[Path, tuple[str, int | None]], *, trust_markers: bool = False) -> None:
    """:class:`InputError` unless the runner may write the stage's settings file and empty its
    folder: the folder is absent, empty or written by the runner (recorded in the state, or,
    with ``trust_markers`` (``--rebuild``), holding the runner's marker for this stage), and
    holds no input (the stage's own results read by a later stage excepted, as wired outputs
    are)."""
    folder, settings_file = _stage_folder(results, stage), results / f"{stage.name}.xml"
    own, position = folder.resolve(), spec.stages.index(stage)
    exists = folder.exists() or folder.is_symlink()
    is_folder = folder.is_dir() and not folder.is_symlink()
    owned = exists and is_folder and (state.owns(stage.name, _relative(folder, results))
                                      or (trust_markers and has_marker(folder, stage.name)))
    for path, (what, reader) in protected.items():
        if path == settings_file.resolve():
            found = f"the runner writes the stage's settings to {settings_file}, which is {what}"
        elif exists and (path == own or path.is_relative_to(own)):
            if owned and reader is not None and reader > position:
                continue  # this stage's results, read by a later stage
            found = (f"its results folder {folder} holds {what} ({path}), which the runner would delete when it "
                     "empties the folder")
        else:
            continue
        raise stage.error(found, element="<Stage name>",
                          expected="a stage name that is not the name of an input inside <results_directory>, "
                                   "or the inputs outside the results folder")
    if not exists or owned or (is_folder and not any(folder.iterdir())):
        return
    how = f"not recorded in {state.path}"
    if state.damaged is not None:
        how = f"{state.path} is damaged ({state.damaged}) and the folder holds no {MARKER} marker of the runner"
    raise stage.error(f"its results folder {folder} already exists and was not written by this pipeline ({how}); "
                      "nmsm empties only the stage folders it wrote",
                      element="<Stage name>",
                      expected=f"{folder} moved away or deleted by hand, another stage name or another "
                               "<results_directory>")


def _require_available(stage: StageSpec, unavailable: dict[str, str]) -> None:
    """:class:`InputError` when the stage needs an output of a stage that did not run now."""
    needed = [a for a in (*stage.kind.requires, *stage.kind.uses) if a in unavailable]
    if needed:
        other = unavailable[needed[0]]
        raise stage.error(f"needs the outputs of stage '{other}' ({needed[0]}), which is not up to date and was "
                          "not selected", expected=f"stage '{other}' selected too, or run first")


def _run_stage(stage: StageSpec, settings: StageSettings, settings_file: Path, folder: Path, results: Path,
               digest: str, state: PipelineState, cache: DigestCache, wired: dict[str, str],
               options: dict[str, Any]) -> StageOutcome:
    earlier_record = state.records.get(stage.name)
    earlier_settings = settings_file.read_bytes() if settings_file.is_file() else None
    earlier = _set_aside(folder)  # only a folder the runner wrote, or an empty one (_check_stage_folder)
    state.forget(stage.name)
    folder.mkdir(parents=True)
    write_marker(folder, stage.name)
    state.claim(stage.name, _relative(folder, results))
    text = settings.text(settings_file, results)
    settings_file.write_text(text, encoding="utf-8")
    began = time.perf_counter()
    try:
        result = stage.kind.load_run()(settings_file, **{**stage.kind.run_options, **options})
    except BaseException as exc:
        diagnosis = getattr(exc, "last_iterate_path", None) is not None
        if _restore(folder, earlier, settings_file, earlier_settings, keep=diagnosis) and earlier_record is not None:
            state.record(earlier_record)  # its input digest differs: the next run redoes the stage
        if isinstance(exc, InputError):
            _point_at_user_settings(exc, settings_file, text, settings)
        raise
    if earlier is not None:
        shutil.rmtree(earlier)
    wall = time.perf_counter() - began
    outputs = stage.kind.load_outputs()(settings, folder)
    record = StageRecord(
        name=stage.name,
        kind=stage.kind.code,
        tool=stage.kind.tool_element,
        settings_file=_relative(settings_file, results),
        results_directory=_relative(folder, results),
        input_digest=digest,
        outputs={k: _relative(v, results) for k, v in outputs.items()},
        output_digest=cache.folder(folder),
        finished=datetime.datetime.now().isoformat(timespec="seconds"),
        wall_time=wall,
    )
    state.record(record)
    return StageOutcome(stage.name, stage.kind.code, stage.kind.label, RAN, wall, settings_file, folder, outputs,
                        wired, result)


def _set_aside(folder: Path) -> Path | None:
    """Move an existing stage folder to a hidden sibling while the stage runs again (None
    when there is none), so that a failed or stopped run can put it back."""
    if not folder.exists():
        return None
    aside = folder.with_name(f".{folder.name}.earlier")
    if aside.exists():
        shutil.rmtree(aside)
    folder.rename(aside)
    return aside


def _restore(folder: Path, earlier: Path | None, settings_file: Path, settings: bytes | None, *,
             keep: bool) -> bool:
    """After a failed or stopped stage, keep the last finished results; returns whether they
    are back in place.

    Unless ``keep``, what the run wrote is removed and the earlier results and settings copy
    are put back. With ``keep`` (a solver failure whose last iterate and diagnosis the tool
    saved in the stage folder) the run's folder stays, and the earlier results go into its
    ``superseded/`` (or ``superseded/earlier_stage_run/`` if the tool made one)."""
    if not keep:
        shutil.rmtree(folder, ignore_errors=True)
        if earlier is not None:
            earlier.rename(folder)
        if settings is not None:
            settings_file.write_bytes(settings)
        return earlier is not None
    if earlier is not None:
        target = folder / "superseded"
        if target.exists():
            target = target / "earlier_stage_run"
        target.parent.mkdir(parents=True, exist_ok=True)
        earlier.rename(target)
    return False


def _point_at_user_settings(exc: InputError, settings_file: Path, text: str, settings: StageSettings) -> None:
    """Make an error at a line of the settings copy the runner wrote (``settings_file``,
    ``text``) name the user's file (the stage's settings file, or the pipeline file for
    embedded settings) and the line the element has there. Elements the runner added
    (rewired inputs, the results folder) have no such line: the error is left as it is."""
    if exc.file is None or exc.line is None:
        return
    try:
        if Path(exc.file).resolve() != settings_file.resolve():
            return
        written = etree.fromstring(text.encode(), xml_parser())
    except (OSError, etree.XMLSyntaxError):
        return
    lines: dict[int, int] = {}
    for copy, original in zip(written.iter(), settings.root.iter()):
        if copy.sourceline is not None and original.sourceline is not None:
            lines.setdefault(copy.sourceline, original.sourceline)
    line = lines.get(exc.line)
    if line is None:
        return
    exc.file, exc.line = str(settings.origin), line
    exc.args = (exc._compose(),)


def run_pipeline_file(pipeline_file: str | os.PathLike[str], **options: Any) -> PipelineRun:
    """Read and run a pipeline file; ``options`` as :func:`run_pipeline`."""
    return run_pipeline(read_pipeline(pipeline_file), **options)

"""The runs of a batch: sweeps expanded into variants, each run's settings built and checked.

A ``<Run>`` is one run; a ``<Sweep>`` is one run per combination of its parameters' values
(a grid) or per ``<Variant>``. A run's settings are its settings file with

* each swept element (an ElementPath below the tool element, e.g.
  ``RCNLParameterTermSet/RCNLParameterTerm[type='max_isometric_force_scale']/lower_bounds``)
  set to the variant's value,
* ``<initial_guess_directory>`` pointed at the parent's results (``<warm_start_from>``),
* ``<results_directory>`` pointed at the run's folder in the batch's results folder,
* every other relative path made absolute (:class:`~nmsm.tools.pipeline.stage_settings.StageSettings`),

and are written to ``<results>/<run>.xml`` (a settings file ``nmsm run`` accepts) when the
run starts. :func:`check_runs` reads every run's settings as its tool will before any run
starts: a swept element that is not in the settings file, or a value its tool cannot read,
is an :class:`~nmsm.errors.InputError` at the batch file; a settings file that its tool
cannot read at all is that run's failure (the other runs go on).
"""

from __future__ import annotations

import itertools
import re
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import attrs

from nmsm.batch.batch_file import BatchSpec, Entry, Parameter
from nmsm.errors import InputError, NmsmError
from nmsm.io.xml_input import set_element_text

if TYPE_CHECKING:
    from nmsm.tools.pipeline.kinds import StageKind
    from nmsm.tools.pipeline.stage_settings import StageSettings

#: the path element a warm start sets
WARM_START_ELEMENT = "initial_guess_directory"
_UNSAFE = re.compile(r"[^A-Za-z0-9.+-]+")


@attrs.frozen
class RunPlan:
    """One run of the batch, as sent to a worker (plain data: paths, texts).

    ``name``: the run's name (``<sweep>/<variant>`` for a sweep's variant); ``entry``: the
    ``<Run>``/``<Sweep>`` it comes from; ``kind``: ``"settings"`` or ``"pipeline"``;
    ``source``: the settings or pipeline file; ``folder``: its results folder;
    ``settings_copy``: where its settings are written (``<results>/<name>.xml``);
    ``overrides``: ``(element path, value)`` set in the settings; ``varied``:
    ``(parameter, value)``; ``warm_start``: the parent's results folder; ``depends_on``: names
    of the runs it waits for; ``results_root``: the batch's results folder.
    """

    name: str
    entry: str
    variant: str
    patient: str
    kind: str
    source: Path
    folder: Path
    settings_copy: Path
    results_root: Path
    overrides: tuple[tuple[str, str], ...] = ()
    varied: tuple[tuple[str, str], ...] = ()
    warm_start: Path | None = None
    depends_on: tuple[str, ...] = ()


def folder_name(text: str) -> str:
    """``text`` as a folder name: runs of characters other than letters, digits, ``.``,
    ``+``, ``-`` become ``_``."""
    return _UNSAFE.sub("_", text).strip("_") or "_"


def _variants(entry: Entry) -> list[tuple[str, tuple[tuple[str, str], ...]]]:
    """``(variant name, ((parameter, value), ...))`` of a sweep, in file order (grid: the
    first parameter varies slowest)."""
    names = [p.name for p in entry.parameters]
    if entry.variants:
        return [(v.name, tuple((n, v.values[n]) for n in names)) for v in entry.variants]
    out = []
    for combination in itertools.product(*(p.values for p in entry.parameters)):
        varied = tuple(zip(names, combination))
        out.append(("_".join(f"{n}={folder_name(v)}" for n, v in varied), varied))
    return out


def expand(spec: BatchSpec) -> list[RunPlan]:
    """Every run of the batch (sweeps expanded), dependencies not yet linked
    (:func:`nmsm.batch.graph.link`)."""
    root = spec.results_directory
    plans: list[RunPlan] = []
    for entry in spec.entries:
        if not entry.is_sweep:
            plans.append(RunPlan(name=entry.name, entry=entry.name, variant="", patient=entry.patient,
                                 kind=entry.kind, source=entry.file, folder=root / entry.folder,
                                 settings_copy=root / f"{entry.folder}.xml", results_root=root))
            continue
        by_name = {p.name: p for p in entry.parameters}
        for variant, varied in _variants(entry):
            overrides = tuple((element, value) for name, value in varied for element in by_name[name].elements)
            plans.append(RunPlan(name=f"{entry.name}/{variant}", entry=entry.name, variant=variant,
                                 patient=entry.patient, kind=entry.kind, source=entry.file,
                                 folder=root / entry.folder / variant,
                                 settings_copy=root / entry.folder / f"{variant}.xml", results_root=root,
                                 overrides=overrides, varied=varied))
    return plans


def tool_kind(settings_file: Path) -> StageKind:
    """The pipeline stage kind (:mod:`nmsm.tools.pipeline.kinds`) of a settings file."""
    from nmsm.tools.dispatch import tool_element_name
    from nmsm.tools.pipeline.kinds import kind_for_element

    return kind_for_element(tool_element_name(settings_file), file=settings_file)


def load_settings(plan: RunPlan, *, variant: bool = True) -> tuple[StageKind, StageSettings]:
    """The run's settings as its tool will read them (module docstring); ``variant=False``:
    the settings file without the swept values and the warm start, only the results folder set."""
    from nmsm.io.settings.document import TOOL_ELEMENTS
    from nmsm.tools.pipeline.stage_settings import StageSettings

    kind = tool_kind(plan.source)
    settings = StageSettings.from_file(plan.source, kind.load_settings_class(),
                                       upgrade=kind.tool_element in TOOL_ELEMENTS)
    if variant:
        for path, value in plan.overrides:
            for element in settings.tool.findall(path):
                set_element_text(element, value)
    if variant and plan.warm_start is not None:
        settings.set_path(WARM_START_ELEMENT, plan.warm_start)
    settings.set_path("results_directory", plan.folder)
    settings.absolutize()
    return kind, settings


def settings_text(plan: RunPlan) -> str:
    """The text of ``plan.settings_copy``."""
    _, settings = load_settings(plan)
    return settings.text(plan.settings_copy, plan.results_root)


def _parse(kind: StageKind, settings: StageSettings) -> None:
    """:class:`InputError` (or another :class:`NmsmError`) when the tool would refuse ``settings``."""
    from nmsm.tools.pipeline.validation import parse_settings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        parsed = parse_settings(settings)
        check = kind.load_validate()
        if check is not None:
            check(parsed)


def _check_elements(spec: BatchSpec, entry: Entry, settings: StageSettings) -> None:
    """Every swept element path matches exactly one element of the settings file."""
    tool = settings.tool
    for parameter in entry.parameters:
        for path in parameter.elements:
            try:
                found = tool.findall(path)
            except SyntaxError as exc:
                raise spec.error(f"sweep '{entry.name}', parameter '{parameter.name}': '{path}' is not an element "
                                 f"path ({exc})", line=parameter.line, element="<element>",
                                 expected="tags separated by '/', optionally [k] or [tag='text'] or "
                                          "[@attribute='value'], below the tool element") from None
            if len(found) != 1:
                what = "no element" if not found else f"{len(found)} elements"
                raise spec.error(f"sweep '{entry.name}', parameter '{parameter.name}': '{path}' matches {what} of "
                                 f"<{settings.tool_tag}> in {entry.file}", line=parameter.line, element="<element>",
                                 expected="the path of one element below the tool element"
                                          + (" (pick one with [k], [type='...'] or [@name='...'])" if found else ""))
            if len(found[0]):
                raise spec.error(f"sweep '{entry.name}', parameter '{parameter.name}': '{path}' is a block "
                                 f"(<{found[0].tag}> holds elements), not a value", line=parameter.line,
                                 element="<element>", expected="the path of an element holding a value")


def _parameter_of(entry: Entry, name: str) -> Parameter:
    return next(p for p in entry.parameters if p.name == name)


def check_runs(spec: BatchSpec, plans: list[RunPlan]) -> dict[str, str]:
    """Check every run's settings before any run starts (module docstring); returns
    ``{run name: message}`` of the runs whose settings or pipeline file cannot be read."""
    from nmsm.tools.pipeline.pipeline_file import read_pipeline

    broken: dict[str, str] = {}
    entries = {e.name: e for e in spec.entries}
    for entry in spec.entries:
        runs = [p for p in plans if p.entry == entry.name]
        try:
            if entry.kind == "pipeline":
                read_pipeline(entry.file)
                continue
            kind, base = load_settings(runs[0], variant=False)
        except NmsmError as exc:
            broken.update({plan.name: str(exc) for plan in runs})
            continue
        if entry.warm_start_from is not None and not base.has_field(WARM_START_ELEMENT):
            raise spec.error(f"'{entry.name}' starts from '{entry.warm_start_from}', but <{base.tool_tag}> has "
                             f"no <{WARM_START_ELEMENT}>", line=entry.line, element="<warm_start_from>",
                             expected="a warm start only for Tracking, Verification and Design Optimization")
        _check_elements(spec, entry, base)
        try:
            _parse(kind, base)
        except NmsmError as exc:
            broken.update({plan.name: str(exc) for plan in runs})
            continue
        for plan in runs:
            if not plan.overrides:
                continue
            try:
                kind, settings = load_settings(plan)
                _parse(kind, settings)
            except NmsmError as exc:
                varied = ", ".join(f"{n} = '{v}'" for n, v in plan.varied)
                line = _parameter_of(entries[plan.entry], plan.varied[0][0]).line
                raise spec.error(f"sweep '{entry.name}', variant '{plan.variant}' ({varied}): its settings do not "
                                 f"read: {exc}", line=line, element="<values>") from None
    return broken

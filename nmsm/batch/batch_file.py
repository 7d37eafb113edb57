"""Reading a batch file (``nmsm batch BATCH.xml``); the format is in docs/batch.md.

::

    <NMSMPipelineDocument Version="1.5.3">
      <BatchTool name="cohort">
        <results_directory>batch_results</results_directory>
        <RunList>
          <Run name="p01" patient="P01"><pipeline_file>p01/pipeline.xml</pipeline_file></Run>
          <Sweep name="p01_do" patient="P01">
            <settings_file>p01/do.xml</settings_file>
            <warm_start_from>p01/vo</warm_start_from>
            <Parameter name="strength">
              <element>RCNLParameterTermSet/RCNLParameterTerm[type='max_isometric_force_scale']/lower_bounds</element>
              <values>0.6 0.8 1.0</values>
            </Parameter>
          </Sweep>
        </RunList>
      </BatchTool>
    </NMSMPipelineDocument>

Relative paths resolve against the batch file's folder. Only the file's own structure is
checked here; the element paths, values and dependencies are checked when the runs are
expanded (:mod:`nmsm.batch.sweep`, :mod:`nmsm.batch.graph`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.settings.document import elements, read_tool_element
from nmsm.io.xml_input import element_text

TOOL = "BatchTool"
RUN, SWEEP = "Run", "Sweep"
#: names of runs, sweeps, parameters and variants: one folder name each
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.=-]*$")
NAME_RULE = "letters, digits, '_', '-', '.', '=' (not starting with '.' or '-')"
_ENTRY_ELEMENTS = ("settings_file", "pipeline_file", "depends_on", "warm_start_from", "results_directory",
                   "Parameter", "Variant")


@attrs.frozen
class Parameter:
    """A swept quantity: the settings elements it sets (ElementPath below the tool element,
    each matching one element) and, for a grid, its values (one text each)."""

    name: str
    elements: tuple[str, ...]
    values: tuple[str, ...]
    line: int | None


@attrs.frozen
class Variant:
    """A named variant of a sweep: parameter name -> value text."""

    name: str
    values: dict[str, str]
    line: int | None


@attrs.frozen
class Entry:
    """One ``<Run>`` or ``<Sweep>`` of the batch file.

    ``kind``: ``"settings"`` (a tool's settings file, run as ``nmsm run``) or ``"pipeline"``
    (a pipeline file, run as ``nmsm pipeline``); ``folder``: its results folder relative to
    the batch's results folder (default: its name); ``warm_start_from``: a run's name, or
    ``run/stage`` for a pipeline run's stage; ``variants`` empty for a grid sweep.
    """

    name: str
    is_sweep: bool
    kind: str
    file: Path
    folder: str
    patient: str
    depends_on: tuple[str, ...]
    warm_start_from: str | None
    parameters: tuple[Parameter, ...]
    variants: tuple[Variant, ...]
    line: int | None


@attrs.frozen
class BatchSpec:
    """A parsed batch file."""

    file: Path
    name: str
    results_directory: Path
    entries: tuple[Entry, ...]

    def error(self, message: str, *, line: int | None = None, element: str | None = None,
              expected: str | None = None) -> InputError:
        return InputError(message, file=self.file, line=line, element=element, expected=expected)


def _name(element: etree._Element, path: Path, what: str) -> str:
    name = element.get("name") or ""
    if not NAME.match(name):
        raise InputError(f"{what} name '{name}' cannot name a folder" if name else f"{what} without a name",
                         file=path, line=element.sourceline, element=f"<{element.tag} name>", expected=NAME_RULE)
    return name


def _values(element: etree._Element | None) -> tuple[str, ...]:
    """``<values>0.5 0.6</values>``, or ``<values><value>0.5 0.5</value>...</values>`` for
    values that hold spaces."""
    if element is None:
        return ()
    items = [c for c in elements(element) if c.tag == "value"]
    if items:
        return tuple(element_text(c).strip() for c in items)
    return tuple(element_text(element).split())


def _parameter(element: etree._Element, path: Path) -> Parameter:
    name = _name(element, path, "parameter")
    paths = tuple(element_text(e).strip() for e in element.findall("element"))
    if not paths or not all(paths):
        raise InputError(f"parameter '{name}' names no settings element", file=path, line=element.sourceline,
                         element="<element>", expected="one or more <element> with the path of a settings element "
                                                       "below the tool element, e.g. RCNLCostTermSet/"
                                                       "RCNLCostTerm[type='controller_tracking']/max_allowable_error")
    for child in elements(element):
        if child.tag not in ("element", "values"):
            raise InputError(f"unknown element <{child.tag}> in <Parameter>", file=path, line=child.sourceline,
                             expected="<element> and <values>")
    return Parameter(name, paths, _values(element.find("values")), element.sourceline)


def _variant(element: etree._Element, path: Path, parameters: dict[str, Parameter]) -> Variant:
    name = _name(element, path, "variant")
    values: dict[str, str] = {}
    for child in elements(element):
        if child.tag not in parameters:
            raise InputError(f"variant '{name}' gives <{child.tag}>, which is no parameter of its sweep",
                             file=path, line=child.sourceline,
                             expected="one element per parameter: " + ", ".join(f"<{p}>" for p in parameters))
        values[str(child.tag)] = element_text(child).strip()
    missing = [p for p in parameters if p not in values]
    if missing:
        raise InputError(f"variant '{name}' gives no value for {', '.join(missing)}", file=path,
                         line=element.sourceline, expected="one element per parameter: "
                                                           + ", ".join(f"<{p}>" for p in parameters))
    return Variant(name, values, element.sourceline)


def _entry(element: etree._Element, path: Path) -> Entry:
    is_sweep = element.tag == SWEEP
    what = "sweep" if is_sweep else "run"
    name = _name(element, path, what)
    for child in elements(element):
        if child.tag not in _ENTRY_ELEMENTS or (not is_sweep and child.tag in ("Parameter", "Variant")):
            allowed = _ENTRY_ELEMENTS if is_sweep else _ENTRY_ELEMENTS[:5]
            raise InputError(f"unknown element <{child.tag}> in <{element.tag} name=\"{name}\">", file=path,
                             line=child.sourceline, expected="one of " + ", ".join(f"<{a}>" for a in allowed))
    settings, pipeline = element.find("settings_file"), element.find("pipeline_file")
    given = [e for e in (settings, pipeline) if e is not None and element_text(e).strip()]
    if len(given) != 1:
        raise InputError(f"{what} '{name}' needs exactly one of <settings_file> and <pipeline_file>", file=path,
                         line=element.sourceline, element=f"<{element.tag}>",
                         expected="<settings_file> (a tool's settings) or <pipeline_file> (a pipeline file)")
    source = given[0]
    kind = "settings" if source.tag == "settings_file" else "pipeline"
    if is_sweep and kind == "pipeline":
        raise InputError(f"sweep '{name}' names a pipeline file", file=path, line=source.sourceline,
                         element="<pipeline_file>", expected="<settings_file>: a sweep varies one tool's settings")
    file = resolve_path(element_text(source).strip(), settings_file=path, line=source.sourceline,
                        element=str(source.tag), kind="file")
    folder_element = element.find("results_directory")
    folder = element_text(folder_element).strip() if folder_element is not None else ""
    if folder:
        relative = Path(folder.replace("\\", "/"))
        if relative.is_absolute() or ".." in relative.parts or any(p.startswith(".") for p in relative.parts):
            raise InputError(f"'{folder}' is not a folder inside the batch's results folder", file=path,
                             line=folder_element.sourceline, element="<results_directory>",
                             expected="a relative path without '..' or hidden parts, e.g. P01/do")
        folder = relative.as_posix()
    depends = tuple(n for e in element.findall("depends_on") for n in element_text(e).split())
    warm = element_text(element.find("warm_start_from")).strip() or None
    parameters = tuple(_parameter(e, path) for e in element.findall("Parameter"))
    by_name: dict[str, Parameter] = {}
    for parameter in parameters:
        if parameter.name in by_name:
            raise InputError(f"parameter '{parameter.name}' given twice in sweep '{name}'", file=path,
                             line=parameter.line, element="<Parameter name>", expected="distinct names")
        by_name[parameter.name] = parameter
    variants = tuple(_variant(e, path, by_name) for e in element.findall("Variant"))
    if is_sweep:
        _check_sweep(name, element, path, parameters, variants)
    return Entry(name=name, is_sweep=is_sweep, kind=kind, file=file, folder=folder or name,
                 patient=element.get("patient", ""), depends_on=depends, warm_start_from=warm,
                 parameters=parameters, variants=variants, line=element.sourceline)


def _check_sweep(name: str, element: etree._Element, path: Path, parameters: tuple[Parameter, ...],
                 variants: tuple[Variant, ...]) -> None:
    if not parameters:
        raise InputError(f"sweep '{name}' has no <Parameter>", file=path, line=element.sourceline,
                         expected="one or more <Parameter> naming settings elements and their values")
    for parameter in parameters:
        if variants and parameter.values:
            raise InputError(f"parameter '{parameter.name}' of sweep '{name}' has <values> and the sweep has "
                             "<Variant>s", file=path, line=parameter.line, element="<values>",
                             expected="either <values> on every parameter (a grid) or <Variant> elements")
        if not variants and not parameter.values:
            raise InputError(f"parameter '{parameter.name}' of sweep '{name}' has no values", file=path,
                             line=parameter.line, element="<values>",
                             expected="<values>v1 v2 ...</values> (a grid), or <Variant> elements")
    seen: set[str] = set()
    for variant in variants:
        if variant.name in seen:
            raise InputError(f"variant '{variant.name}' given twice in sweep '{name}'", file=path,
                             line=variant.line, element="<Variant name>", expected="distinct names")
        seen.add(variant.name)


def read_batch(path: str | os.PathLike[str], results_directory: str | os.PathLike[str] | None = None) -> BatchSpec:
    """Parse and check a batch file; ``results_directory`` replaces its ``<results_directory>``."""
    path = Path(path).resolve()
    tool = read_tool_element(path, TOOL, " (nmsm print-xml batch shows one)")
    for child in elements(tool):
        if child.tag not in ("results_directory", "RunList"):
            raise InputError(f"unknown element <{child.tag}> in <{TOOL}>", file=path, line=child.sourceline,
                             expected="<results_directory> and <RunList>")
    if results_directory is not None:
        results = Path(results_directory).resolve()
    else:
        text = element_text(tool.find("results_directory")).strip()
        if not text:
            raise InputError("no results folder", file=path, line=tool.sourceline, element="<results_directory>",
                             expected="<results_directory> naming the batch's results folder (or nmsm batch -o)")
        results = resolve_path(text, settings_file=path, base=path.parent, must_exist=False).resolve()
    if results.exists() and not results.is_dir():
        raise InputError(f"the results folder {results} is a file", file=path, element="<results_directory>",
                         expected="a folder (absent or a folder)")
    if results == path.parent or path.parent.is_relative_to(results):
        raise InputError(f"the results folder {results} is, or holds, the batch file's folder: the runs' results "
                         "would mix with the inputs", file=path, element="<results_directory>",
                         expected="a folder of its own, e.g. batch_results")
    run_list = tool.find("RunList")
    entries_xml = [c for c in elements(run_list)] if run_list is not None else []
    if not entries_xml:
        raise InputError("no runs", file=path, line=tool.sourceline, element="<RunList>",
                         expected="<RunList> with <Run> and <Sweep> elements")
    entries: list[Entry] = []
    lines: dict[str, int | None] = {}
    for element in entries_xml:
        if element.tag not in (RUN, SWEEP):
            raise InputError(f"unexpected <{element.tag}> in <RunList>", file=path, line=element.sourceline,
                             expected="<Run> and <Sweep> elements")
        entry = _entry(element, path)
        if entry.name in lines:
            raise InputError(f"the name '{entry.name}' is used twice (also at line {lines[entry.name]})", file=path,
                             line=element.sourceline, element=f"<{element.tag} name>",
                             expected="distinct names of runs and sweeps")
        lines[entry.name] = element.sourceline
        entries.append(entry)
    return BatchSpec(file=path, name=tool.get("name", path.stem), results_directory=results,
                     entries=tuple(entries))

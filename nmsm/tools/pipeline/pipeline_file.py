"""Reading a pipeline file (``nmsm pipeline PIPELINE.xml``); the format is in docs/pipeline.md.

::

    <NMSMPipelineDocument Version="1.5.3">
      <PipelineTool name="subject">
        <results_directory>results</results_directory>
        <input_model_file>model.osim</input_model_file>        <!-- optional starting inputs -->
        <StageList>
          <Stage name="jmp"><settings_file>JMPSettings.xml</settings_file></Stage>
          <Stage name="mtp">
            <keep_settings_inputs>data_directory</keep_settings_inputs>
            <MuscleTendonPersonalizationTool> ... </MuscleTendonPersonalizationTool>
          </Stage>
        </StageList>
      </PipelineTool>
    </NMSMPipelineDocument>

Relative paths resolve against the pipeline file's folder. Each ``<Stage>`` holds either a
``<settings_file>`` or one embedded tool element; its kind is that tool element.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.settings.document import ROOT, elements, parse_settings_xml, read_tool_element, to_bool
from nmsm.tools.dispatch import SOLVING_TOOLS
from nmsm.tools.pipeline.artifacts import INPUT_ELEMENTS
from nmsm.tools.pipeline.kinds import StageKind, kind_for_element
from nmsm.io.xml_input import element_text
from nmsm.tools.pipeline.stage_settings import StageSettings

TOOL = "PipelineTool"
_STAGE_ELEMENTS = ("is_enabled", "settings_file", "keep_settings_inputs", "accept_unconverged")
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
#: longest stage name: its results folder's aside copy ``.<name>.earlier`` is one path
#: component, at most 255 bytes on common file systems (a longer name was an OSError
#: traceback, "File name too long", when the stage ran)
MAX_NAME = 255 - len("..earlier")


@attrs.frozen(eq=False)
class StageSpec:
    """One ``<Stage>``: its name, kind, settings (file or embedded) and source line.

    ``keep``: settings elements the runner must leave as the settings give them
    (``keep_settings_inputs``), e.g. ``input_model_file`` for a tool run on another model.
    ``accept_unconverged``: the stage writes its results although its solve stopped before
    its stopping criterion, stamped as unconverged (``<accept_unconverged>``;
    :mod:`nmsm.core.unconverged`).
    """

    name: str
    kind: StageKind
    settings_file: Path | None
    embedded: etree._Element | None
    keep: tuple[str, ...]
    enabled: bool
    file: Path
    line: int | None
    accept_unconverged: bool = False

    def load_settings(self) -> StageSettings:
        """The stage's settings tree (a fresh copy; old schemas upgraded)."""
        cls = self.kind.load_settings_class()
        if self.settings_file is not None:
            return StageSettings.from_file(self.settings_file, cls, upgrade=_is_tool_schema(self.kind))
        assert self.embedded is not None
        return StageSettings.from_element(self.embedded, self.file, cls)

    def error(self, message: str, *, element: str | None = None, expected: str | None = None) -> InputError:
        """An :class:`InputError` at this stage's ``<Stage>`` element."""
        return InputError(f"stage '{self.name}' ({self.kind.code}): {message}", file=self.file, line=self.line,
                          element=element, expected=expected)


@attrs.frozen(eq=False)
class PipelineSpec:
    """A parsed pipeline file."""

    file: Path
    name: str
    results_directory: Path
    inputs: dict[str, Path]  #: artifact -> path given in the pipeline file
    input_lines: dict[str, int | None]
    stages: tuple[StageSpec, ...]


def _is_tool_schema(kind: StageKind) -> bool:
    """Whether the settings are read by :func:`read_settings_document` (a tool of the original)."""
    from nmsm.io.settings.document import TOOL_ELEMENTS

    return kind.tool_element in TOOL_ELEMENTS


def _text(element: etree._Element | None) -> str:
    return element_text(element)


def read_pipeline(path: str | os.PathLike[str]) -> PipelineSpec:
    """Parse and check a pipeline file (stage names, kinds, settings files exist)."""
    path = Path(path).resolve()
    tool = read_tool_element(path, TOOL)
    results_text = _text(tool.find("results_directory"))
    if not results_text:
        raise InputError("no results folder", file=path, line=tool.sourceline, element="<results_directory>",
                         expected="<results_directory> naming the folder of the results tree")
    results = resolve_path(results_text, settings_file=path, base=path.parent, must_exist=False)
    if results.exists() and not results.is_dir():  # was a FileExistsError traceback when the run made it
        element = tool.find("results_directory")
        raise InputError(f"'{results_text}' is a file ({results}), not a folder", file=path,
                         line=element.sourceline, element="<results_directory>",
                         expected="a folder for the results tree (absent or a folder)")
    inputs: dict[str, Path] = {}
    lines: dict[str, int | None] = {}
    for artifact, element_name in INPUT_ELEMENTS.items():
        element = tool.find(element_name)
        if _text(element):
            kind = "file" if artifact in ("model", "osimx") else "dir"
            inputs[artifact] = resolve_path(_text(element), settings_file=path, line=element.sourceline,
                                            element=element_name, kind=kind)
            lines[artifact] = element.sourceline
    known = {"results_directory", "StageList", *INPUT_ELEMENTS.values()}
    for child in elements(tool):
        if child.tag not in known:
            raise InputError(f"unknown element <{child.tag}> in <{TOOL}>", file=path, line=child.sourceline,
                             expected="one of " + ", ".join(f"<{k}>" for k in sorted(known)))
    stage_list = tool.find("StageList")
    if stage_list is None or not [c for c in elements(stage_list)]:
        raise InputError("no stages", file=path, line=tool.sourceline, element="<StageList>",
                         expected="<StageList> with at least one <Stage>")
    stages: list[StageSpec] = []
    names: dict[str, int | None] = {}
    for element in elements(stage_list):
        if element.tag != "Stage":
            raise InputError(f"unexpected <{element.tag}> in <StageList>", file=path, line=element.sourceline,
                             expected="<Stage> elements")
        stage = _read_stage(element, path, [s.kind.code for s in stages])
        if stage.name in names:
            raise InputError(f"stage name '{stage.name}' used twice (also at line {names[stage.name]})", file=path,
                             line=element.sourceline, element="<Stage name>", expected="distinct stage names")
        names[stage.name] = element.sourceline
        stages.append(stage)
    return PipelineSpec(file=path, name=tool.get("name", path.stem), results_directory=results, inputs=inputs,
                        input_lines=lines, stages=tuple(stages))


def _read_stage(element: etree._Element, path: Path, earlier_codes: list[str]) -> StageSpec:
    line = element.sourceline
    tools = [c for c in elements(element) if c.tag not in _STAGE_ELEMENTS]
    settings_element = element.find("settings_file")
    settings_text = _text(settings_element)
    if settings_text and tools:
        raise InputError("both <settings_file> and an embedded tool element", file=path, line=line,
                         element="<Stage>", expected="one of the two")
    settings_file: Path | None = None
    embedded: etree._Element | None = None
    if settings_text:
        settings_file = resolve_path(settings_text, settings_file=path, line=settings_element.sourceline,
                                     element="settings_file", kind="file")
        tool_tag = _settings_tool_tag(settings_file)
        kind = kind_for_element(tool_tag, file=settings_file)
    elif len(tools) == 1:
        embedded = tools[0]
        kind = kind_for_element(str(embedded.tag), file=path, line=embedded.sourceline)
    else:
        raise InputError(f"{len(tools)} embedded tool elements and no <settings_file>", file=path, line=line,
                         element="<Stage>", expected="<settings_file> or exactly one tool element")
    name = element.get("name") or _default_name(kind.code, earlier_codes)
    if not _NAME.match(name):
        raise InputError(f"stage name '{name}' cannot name a folder", file=path, line=line, element="<Stage name>",
                         expected="letters, digits, '_', '-', '.' (not starting with '.')")
    if len(name) > MAX_NAME:
        raise InputError(f"stage name of {len(name)} characters ('{name[:20]}...') is too long for a folder name",
                         file=path, line=line, element="<Stage name>", expected=f"at most {MAX_NAME} characters")
    enabled = _boolean(element, "is_enabled", path, default=True)
    accept = _boolean(element, "accept_unconverged", path, default=False)
    if accept and kind.tool_element not in SOLVING_TOOLS:
        raise InputError(f"stage '{name}' ({kind.code}) solves no optimization", file=path,
                         line=element.find("accept_unconverged").sourceline, element="<accept_unconverged>",
                         expected="the element only in stages of JMP, MTP, NCP, GCP, TO, VO or DO")
    keep_element = element.find("keep_settings_inputs")
    keep = tuple(_text(keep_element).split())
    _check_keep(keep, kind, name, path, keep_element)
    return StageSpec(name=name, kind=kind, settings_file=settings_file, embedded=embedded, keep=keep,
                     enabled=enabled, file=path, line=line, accept_unconverged=accept)


def _boolean(stage: etree._Element, tag: str, path: Path, *, default: bool) -> bool:
    """The stage's ``<tag>`` as a boolean (``default`` when missing or empty)."""
    element = stage.find(tag)
    text = _text(element)
    try:
        return to_bool(text) if text else default
    except ValueError:
        raise InputError(f"'{text}' is not a boolean", file=path, line=element.sourceline, element=f"<{tag}>",
                         expected="true or false") from None


def _check_keep(keep: tuple[str, ...], kind: StageKind, name: str, path: Path,
                element: etree._Element | None) -> None:
    """Each ``keep_settings_inputs`` name is an element the runner rewires for this kind (a
    misspelled one kept nothing: the element was rewired, e.g. JMP's model given to a stage
    meant to run on its own)."""
    from nmsm.io.names import close_matches
    from nmsm.tools.pipeline.wiring import is_kept

    keys = kind.rewired_keys()
    if keys is None:
        return
    for kept in keep:
        if any(is_kept(key, (kept,)) for key in keys):
            continue
        names = sorted({*keys, *(k.rsplit("/", 1)[-1] for k in keys)})
        close = close_matches(kept, names, n=2)
        hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
        raise InputError(
            f"stage '{name}' ({kind.code}): '{kept}' is no element the runner rewires for this stage, so keeping "
            f"it would keep nothing{hint}", file=path, line=element.sourceline if element is not None else None,
            element="<keep_settings_inputs>", expected="names (or paths) among " + ", ".join(names))


def _default_name(code: str, earlier_codes: list[str]) -> str:
    count = earlier_codes.count(code)
    return code if count == 0 else f"{code}{count + 1}"


def _settings_tool_tag(settings_file: Path) -> str:
    """The tool element of a stage settings file, old schemas included."""
    from nmsm.io.settings.upgrade import detect_schema

    root = parse_settings_xml(settings_file)
    if detect_schema(root) != "current":
        from nmsm.io.settings.reader import read_settings_document

        return read_settings_document(settings_file, check_paths=False).tool
    tools = list(elements(root))
    if root.tag != ROOT or len(tools) != 1:
        raise InputError("not a settings file with one tool element", file=settings_file, line=root.sourceline,
                         expected=f"<{ROOT}> holding one tool element")
    return str(tools[0].tag)

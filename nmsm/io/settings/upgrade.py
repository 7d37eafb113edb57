"""Upgrade older settings schemas to the current one (``docs/settings-upgrade.md``).

Schemas recognized (:func:`detect_schema`):

``current``        ``<NMSMPipelineDocument Version="1.x">`` + tool element; elements that an
                   earlier 1.x release wrote and the current schema replaced are translated
                   (:mod:`nmsm.io.settings.upgrade_released`).
``opensim-2023``   root ``<OpenSimDocument>`` (2021-2023 nmsm-core settings: JMP, MTP, NCP,
                   GCP), with OpenSim-style ``<objects>``/``<groups>`` set wrappers.
``treatment-0.1``  ``<NMSMPipelineDocument Version="0.x">`` TO/VO/DO files (jerk controls,
                   separate tracking/minimization/path/terminal term sets).
``gpops-0.1``      root ``<GpopsDocument>`` solver file.

The upgrade moves the original elements (so errors still point at the old file's lines),
renames what has a current equivalent and replaces what has none by an XML comment, with
a note (a warning when read by :func:`~nmsm.io.settings.reader.read_settings_document`).
"""

from __future__ import annotations

import copy
import os
from pathlib import Path

from lxml import etree

from nmsm.errors import InputError
from nmsm.io.settings import upgrade_legacy_personalization, upgrade_legacy_treatment, upgrade_released
from nmsm.io.settings.classes import SETTINGS_CLASSES
from nmsm.io.settings.document import PIPELINE_VERSION_TEXT, ROOT, TOOL_ELEMENTS, elements, parse_version
from nmsm.io.settings.upgrader import UpgradeResult, Upgrader, child_of

SCHEMAS = ("current", "opensim-2023", "treatment-0.1", "gpops-0.1")


def detect_schema(root: etree._Element) -> str:
    """One of :data:`SCHEMAS` (``current`` for anything not recognized as old: checked later)."""
    if root.tag == "GpopsDocument":
        return "gpops-0.1"
    if root.tag == "OpenSimDocument":
        tools = [c for c in elements(root) if c.tag in TOOL_ELEMENTS]
        return "opensim-2023" if tools else "current"
    if root.tag == ROOT:
        version = parse_version(root.get("Version"))
        if version is not None and version[0] == 0:
            return "treatment-0.1"
    return "current"


def upgrade_tree(root: etree._Element, path: str | os.PathLike[str]) -> UpgradeResult:
    """Upgrade a parsed settings root (a copy; ``root`` is untouched)."""
    path = Path(path)
    schema = detect_schema(root)
    work = copy.deepcopy(root)
    if schema == "current":
        if work.tag != ROOT or not upgrade_released.needed(work):
            return UpgradeResult(work, schema)
        released = Upgrader(work, path, schema)
        upgrade_released.upgrade(released)
        return UpgradeResult(released.root, schema, released.notes)
    found = list(elements(root))
    if schema in ("opensim-2023", "treatment-0.1") and len(found) > 1:  # the upgrade would read the first only
        raise InputError(
            f"<{root.tag}> holds {len(found)} elements: " + ", ".join(f"<{e.tag}> (line {e.sourceline})" for e in found),
            file=path, line=found[1].sourceline, element=f"<{found[1].tag}>",
            expected=f"exactly one tool element in <{root.tag}> (one settings file per tool run)",
        )
    upgrader = Upgrader(work, path, schema)
    if schema == "opensim-2023":
        upgrade_legacy_personalization.upgrade(upgrader)
    elif schema == "treatment-0.1":
        upgrade_legacy_treatment.upgrade(upgrader)
    elif schema == "gpops-0.1":
        upgrade_legacy_treatment.upgrade_gpops(upgrader)
    _note_missing_required(upgrader)
    return UpgradeResult(upgrader.root, schema, upgrader.notes)


def _note_missing_required(up: Upgrader) -> None:
    """Note required elements that the old file did not have (they have no old equivalent)."""
    from nmsm.io.settings.schema import settings_fields

    tool = next(elements(up.root), None)
    cls = SETTINGS_CLASSES.get(str(tool.tag)) if tool is not None else None
    if cls is None:
        return
    for _, spec in settings_fields(cls):
        if not (spec.required or spec.required_element):
            continue
        if spec.kind in ("attribute", "settings_file", "source", "tool", "fields"):
            continue
        tag = spec.container if spec.kind == "blocks" and spec.container else spec.element
        if child_of(tool, tag) is None and not any(child_of(tool, a) is not None for a in spec.aliases):
            up.note(tool, f"<{tag}> is required by the current schema and the old file has no equivalent: add it")


def _output_elements(tool_tag: str) -> set[str]:
    """Element names the current settings class of ``tool_tag`` declares as outputs (results folders)."""
    from nmsm.io.settings.schema import settings_fields

    names = {"results_directory"}
    pending = [SETTINGS_CLASSES.get(tool_tag)]
    seen: set[type] = set()
    while pending:
        cls = pending.pop()
        if cls is None or cls in seen:
            continue
        seen.add(cls)
        for _, spec in settings_fields(cls):
            if spec.kind == "path" and spec.output:
                names.add(spec.element)
            if spec.nested is not None:
                pending.append(spec.nested)
    return names


def referenced_paths(roots: list[etree._Element], source: Path) -> tuple[dict[Path, str], dict[Path, str]]:
    """The existing files and input folders that the settings trees ``roots`` (the old file
    and its upgraded form) name, as nmsm resolves them from ``source``'s folder:
    ``({file: what it is}, {folder: what it is})``. Every element whose text names an
    existing file counts (solver settings, model, data files); folders count unless the
    element is a results folder."""
    import warnings

    from nmsm.io.paths import resolve_path

    files: dict[Path, str] = {}
    folders: dict[Path, str] = {}
    outputs: set[str] = {"results_directory"}
    for root in roots:
        tool = next(elements(root), None)
        if tool is not None:
            outputs |= _output_elements(str(tool.tag))
    for root in roots:
        for element in root.iter():
            if not isinstance(element.tag, str) or len(element) or element is root:
                continue
            text = (element.text or "").strip()
            if not text or "\n" in text or len(text) > 4096 or text in ("true", "false") or _is_number(text):
                continue
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    found = resolve_path(text, settings_file=source, must_exist=True, kind="any")
            except (InputError, OSError, ValueError):
                continue
            where = f"<{element.tag}>" + (f" (line {element.sourceline})" if element.sourceline else "")
            if found.is_file():
                files.setdefault(found, f"the file {source.name} names in {where}")
            elif found.is_dir() and element.tag not in outputs:
                folders.setdefault(found, f"the folder {source.name} names in {where}")
    return files, folders


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def upgrade_settings_file(
    source: str | os.PathLike[str], destination: str | os.PathLike[str], *, force: bool = False
) -> UpgradeResult:
    """Write the current-schema form of ``source`` to ``destination``.

    Refused (:class:`InputError`, nothing written): ``destination`` is ``source`` itself (in
    any spelling or link form) or a file ``source`` names (its solver settings, model, data),
    or an existing file inside a data folder it names; an existing ``destination`` without
    ``force``; a missing folder; a folder. The file is written atomically
    (:mod:`nmsm.io.output_file`).
    """
    from nmsm.io.settings.document import parse_settings_xml
    from nmsm.io.output_file import check_output, write_output

    source, destination = Path(source), Path(destination)
    itself = {source: "the settings file being upgraded (this name, a link or another spelling of it)"}
    check_output(destination, force=True, protected=itself, example_name=f"{source.stem}_upgraded.xml")
    root = parse_settings_xml(source)
    result = upgrade_tree(root, source)
    files, folders = referenced_paths([root, result.root], source)
    check_output(destination, force=force, protected={**itself, **files}, protected_folders=folders,
                 example_name=f"{source.stem}_upgraded.xml")
    tree = result.root
    etree.indent(tree, space="\t")
    header = f"<!-- Upgraded by nmsm upgrade-settings from {source.name} (schema {result.schema}). -->\n"
    if result.schema == "current" and result.notes:
        header = (f"<!-- Upgraded by nmsm upgrade-settings from {source.name} (elements of an earlier 1.x release "
                  "translated). -->\n")
    elif result.schema == "current":
        header = f"<!-- {source.name} already uses the current schema; copied by nmsm upgrade-settings. -->\n"
    text = etree.tostring(tree, encoding="unicode")
    write_output(destination, header + text + "\n")
    return result

"""Settings files of the pipeline's own stages (``<ModelAnalysisTool>``,
``<DataPreprocessingTool>``, ``<SurrogateDataTool>``) and of pipeline files.

These tool elements are not tools of the original NMSM Pipeline, so they are read here
rather than by :func:`~nmsm.io.settings.reader.read_settings_document`; the same root
(``<NMSMPipelineDocument Version="1.x">``), version check and declarative settings classes
(:mod:`nmsm.io.settings.schema`) apply. ``nmsm run`` dispatches them through
:data:`NATIVE_RUNNERS`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from nmsm.errors import InputError
from nmsm.io.settings.document import ROOT, SettingsDocument, check_version, elements, parse_settings_xml
from nmsm.io.settings.schema import read_block

#: pipeline-native tool element -> "module:function" taking (settings_file, **options)
NATIVE_RUNNERS: dict[str, str] = {
    "PipelineTool": "nmsm.tools.pipeline.runner:run_pipeline_file",
    "ModelAnalysisTool": "nmsm.tools.pipeline.analysis:run_settings",
    "DataPreprocessingTool": "nmsm.tools.pipeline.preprocess_stage:run_settings",
    "SurrogateDataTool": "nmsm.tools.pipeline.surrogate_stage:run_settings",
}


def native_tool_element(path: str | os.PathLike[str]) -> str | None:
    """The tool element of ``path`` when it is a pipeline-native one, else ``None``."""
    try:
        root = parse_settings_xml(Path(path))
    except InputError:
        return None
    if root.tag != ROOT:
        return None
    tools = list(elements(root))
    if len(tools) == 1 and tools[0].tag in NATIVE_RUNNERS:
        return str(tools[0].tag)
    return None


def read_native_settings(path: str | os.PathLike[str], settings_class: type, tool: str) -> Any:
    """The validated settings of a pipeline-native settings file whose tool element is ``tool``."""
    path = Path(path)
    root = parse_settings_xml(path)
    if root.tag != ROOT:
        raise InputError(f"root element is <{root.tag}>", file=path, line=root.sourceline, element=f"<{root.tag}>",
                         expected=f"<{ROOT}>")
    version = check_version(root, path)
    tools = list(elements(root))
    if len(tools) != 1 or tools[0].tag != tool:
        found = ", ".join(f"<{t.tag}>" for t in tools) or "none"
        raise InputError(f"tool element {found}", file=path, line=root.sourceline, expected=f"one <{tool}>")
    doc = SettingsDocument(path=path, root=root, tool_element=tools[0], version=version)
    return read_block(settings_class, doc, tools[0])

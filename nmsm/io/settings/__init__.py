"""Settings XML of every tool: parsing, old-schema upgrade, validated attrs classes, templates.

doc = read_settings_document("MTPSettings.xml")          # upgrades old schemas (warning)
settings = MuscleTendonPersonalizationSettings.from_document(doc)
settings = read_tool_settings("MTPSettings.xml")          # same, class chosen by tool element
"""

from __future__ import annotations

import os
from typing import Any

from nmsm.io.settings.document import PIPELINE_VERSION_TEXT, TOOL_ELEMENTS, SettingsDocument
from nmsm.io.settings.classes import SETTINGS_CLASSES
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.io.settings.jmp import JointModelPersonalizationSettings
from nmsm.io.settings.mtp import MuscleTendonPersonalizationSettings
from nmsm.io.settings.ncp import NeuralControlPersonalizationSettings
from nmsm.io.settings.solver import OptimalControlSolverSettings
from nmsm.io.settings.treatment import (
    DesignOptimizationSettings,
    TrackingOptimizationSettings,
    VerificationOptimizationSettings,
)
from nmsm.io.settings.reader import read_settings_document

#: short code (``nmsm print-xml``) -> tool element
TOOL_CODES: dict[str, str] = {code: element for element, code in TOOL_ELEMENTS.items()}


def settings_from_document(doc: SettingsDocument) -> Any:
    """The validated settings object of ``doc``'s tool."""
    return SETTINGS_CLASSES[doc.tool].from_document(doc)


def read_tool_settings(path: str | os.PathLike[str], *, check_paths: bool = True) -> Any:
    """Read a settings file and return its tool's validated settings object."""
    return settings_from_document(read_settings_document(path, check_paths=check_paths))


__all__ = [
    "PIPELINE_VERSION_TEXT",
    "SETTINGS_CLASSES",
    "TOOL_CODES",
    "SettingsDocument",
    "read_settings_document",
    "read_tool_settings",
    "settings_from_document",
    "JointModelPersonalizationSettings",
    "MuscleTendonPersonalizationSettings",
    "NeuralControlPersonalizationSettings",
    "GroundContactPersonalizationSettings",
    "TrackingOptimizationSettings",
    "VerificationOptimizationSettings",
    "DesignOptimizationSettings",
    "OptimalControlSolverSettings",
]

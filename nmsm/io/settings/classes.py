"""The settings class of each tool element."""

from __future__ import annotations

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

#: tool element -> settings class
SETTINGS_CLASSES: dict[str, type] = {
    "JointModelPersonalizationTool": JointModelPersonalizationSettings,
    "MuscleTendonPersonalizationTool": MuscleTendonPersonalizationSettings,
    "NeuralControlPersonalizationTool": NeuralControlPersonalizationSettings,
    "GroundContactPersonalizationTool": GroundContactPersonalizationSettings,
    "TrackingOptimizationTool": TrackingOptimizationSettings,
    "VerificationOptimizationTool": VerificationOptimizationSettings,
    "DesignOptimizationTool": DesignOptimizationSettings,
    "OptimalControlSolverSettings": OptimalControlSolverSettings,
}

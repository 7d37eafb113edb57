"""Hook implementations: the module named by this distribution's ``nmsm`` entry point."""

from __future__ import annotations

from nmsm.hookspecs import hookimpl
from nmsm_stroke.scaling import ScaleSynergyActivation
from nmsm_stroke.symmetry import SynergyAmplitudeSymmetry


@hookimpl
def nmsm_cost_terms() -> list[type]:
    return [SynergyAmplitudeSymmetry]


@hookimpl
def nmsm_model_modifiers() -> list[type]:
    return [ScaleSynergyActivation]

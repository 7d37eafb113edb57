"""Settings of Neural Control Personalization (``<NeuralControlPersonalizationTool>``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import attrs

from nmsm.io.term_spec import TermSpec
from nmsm.io.settings.document import SettingsDocument
from nmsm.io.settings.muscle_common import MuscleToolSettings
from nmsm.io.settings.schema import ReadContext, at_least_one, positive, read_block, setting

TOOL_ELEMENT = "NeuralControlPersonalizationTool"

_NCP_TERMS = ({"is_enabled": "true", "type": "moment_tracking", "max_allowable_error": "10"},)


@attrs.frozen(kw_only=True)
class SynergyGroupSettings:
    """One ``<RCNLSynergy>``: a ForceSet group and its number of synergies."""

    muscle_group_name: str = setting(
        "muscle_group_name", kind="text", required=True, example="RightLeg", doc="ForceSet group of the model"
    )
    num_synergies: int = setting(
        "num_synergies",
        kind="integer",
        required=True,
        check=at_least_one,
        example="5",
        doc="Number of synergies of the group",
    )


@attrs.frozen(kw_only=True)
class NeuralControlPersonalizationSettings(MuscleToolSettings):
    """Validated NCP settings; paths resolved relative to the settings file."""

    mtp_results_directory: Path | None = setting(
        "mtp_results_directory",
        kind="path",
        path_kind="dir",
        default=None,
        example="mtp_results",
        doc="MTP results folder (muscleActivations/<trial>_muscleActivations.sto are tracked)",
    )
    enforce_bilateral_symmetry: bool = setting(
        "enforce_bilateral_symmetry",
        kind="boolean",
        default=False,
        doc="Same synergy vectors for the two synergy groups",
    )
    cost_terms: tuple[TermSpec, ...] = setting(
        "RCNLCostTermSet", kind="terms", term_kind="cost", required=True, examples=_NCP_TERMS, doc="NCP cost terms"
    )
    synergy_groups: tuple[SynergyGroupSettings, ...] = setting(
        "RCNLSynergy",
        kind="blocks",
        container="RCNLSynergySet",
        nested=SynergyGroupSettings,
        required=True,
        doc="Synergy groups",
    )
    diff_min_change: float = setting(
        "diff_min_change",
        kind="number",
        default=1e-6,
        check=positive,
        doc="Minimum finite-difference step of the optimizer",
    )
    step_tolerance: float = setting(
        "step_tolerance", kind="number", default=1e-16, check=positive, doc="Step tolerance of the optimizer"
    )
    optimality_tolerance: float = setting(
        "optimality_tolerance", kind="number", default=1e-3, check=positive, doc="Optimality tolerance of the optimizer"
    )
    function_tolerance: float = setting(
        "function_tolerance", kind="number", default=1e-6, check=positive, doc="Function tolerance of the optimizer"
    )
    max_iterations: int = setting(
        "max_iterations", kind="integer", default=1000, check=positive, doc="Maximum iterations of the optimizer"
    )
    max_function_evaluations: int = setting(
        "max_function_evaluations",
        kind="integer",
        default=1_000_000,
        check=positive,
        doc="Maximum cost evaluations of the optimizer",
    )

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if values["enforce_bilateral_symmetry"] and len(values["synergy_groups"]) != 2:
            raise ctx.error(
                "enforce_bilateral_symmetry",
                f"bilateral symmetry needs exactly two synergy groups, found {len(values['synergy_groups'])}",
                "two <RCNLSynergy> elements (left and right)",
            )
        names = [g.muscle_group_name for g in values["synergy_groups"]]
        repeated = sorted({n for n in names if names.count(n) > 1})
        if repeated:
            raise ctx.error(
                "RCNLSynergySet", f"synergy group(s) listed twice: {', '.join(repeated)}", "each group once"
            )

    @classmethod
    def from_document(cls, doc: SettingsDocument) -> NeuralControlPersonalizationSettings:
        doc.require_tool(TOOL_ELEMENT)
        return read_block(cls, doc, doc.tool_element)

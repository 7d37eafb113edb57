"""Settings of Muscle-Tendon Personalization (``<MuscleTendonPersonalizationTool>``).

Includes Muscle-Tendon Length Initialization (shared with NCP) and Synergy Extrapolation.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.io.term_spec import SourceRef, TermSpec
from nmsm.io.settings.document import SettingsDocument
from nmsm.io.settings.muscle_common import MuscleToolSettings
from nmsm.io.settings.schema import ReadContext, at_least_one, positive, read_block, setting

TOOL_ELEMENT = "MuscleTendonPersonalizationTool"
CATEGORIZATIONS = ("trial", "task", "subject")

_MTP_TERMS = ({"is_enabled": "true", "type": "inverse_dynamics_joint_moment", "max_allowable_error": "2.5"},)
_SYNX_TERMS = ({"is_enabled": "true", "type": "measured_inverse_dynamics_joint_moment", "max_allowable_error": "2"},)


@attrs.frozen(kw_only=True)
class SynergyExtrapolationSettings:
    """``<MTPSynergyExtrapolation>``: activations of muscles without EMG from synergies."""

    is_enabled: bool = setting("is_enabled", kind="boolean", default=False, doc="Run synergy extrapolation")
    matrix_factorization_method: str = setting(
        "matrix_factorization_method",
        kind="text",
        default="PCA",
        choices=("PCA", "NMF"),
        doc="Matrix factorization: PCA or NMF",
    )
    number_of_synergies: int | None = setting(
        "number_of_synergies",
        kind="integer",
        default=None,
        check=at_least_one,
        example="3",
        doc="Number of synergies (required when enabled)",
    )
    synergy_extrapolation_categorization: str | None = setting(
        "synergy_extrapolation_categorization",
        kind="text",
        default=None,
        choices=CATEGORIZATIONS,
        example="trial",
        doc="Variability of synergy vectors: trial, task or subject (required when enabled)",
    )
    residual_categorization: str | None = setting(
        "residual_categorization",
        kind="text",
        default=None,
        choices=CATEGORIZATIONS,
        example="task",
        doc="Variability of activation residuals: trial, task or subject (required when enabled)",
    )
    cost_terms: tuple[TermSpec, ...] = setting(
        "RCNLCostTermSet",
        kind="terms",
        term_kind="cost",
        default=(),
        examples=_SYNX_TERMS,
        doc="Synergy extrapolation cost terms",
    )

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if not values["is_enabled"]:
            return
        for key in ("number_of_synergies", "synergy_extrapolation_categorization", "residual_categorization"):
            if values[key] is None:
                raise ctx.error(
                    key, f"<{key}> is required when synergy extrapolation is enabled", f"<{key}> with a value"
                )


@attrs.frozen(kw_only=True)
class MtpTask:
    """One ``<MTPTask>``: which muscle parameters are optimized and the task's cost terms."""

    is_enabled: bool = setting("is_enabled", kind="boolean", required=True, example="true", doc="Run this task")
    index: int | None = setting(
        "index", kind="integer", default=None, example="1", doc="Order of the task (required with more than one task)"
    )
    muscle_specific_electromechanical_delays: bool = setting(
        "muscle_specific_electromechanical_delays",
        kind="boolean",
        required=True,
        example="true",
        doc="One electromechanical delay per muscle (read but unused, as in the original)",
    )
    optimize_electromechanical_delays: bool = setting(
        "optimize_electromechanical_delays", kind="boolean", default=True, doc="Optimize electromechanical delays"
    )
    optimize_activation_time_constants: bool = setting(
        "optimize_activation_time_constants", kind="boolean", default=True, doc="Optimize activation time constants"
    )
    optimize_activation_nonlinearity_constants: bool = setting(
        "optimize_activation_nonlinearity_constants",
        kind="boolean",
        default=True,
        doc="Optimize activation nonlinearity constants",
    )
    optimize_emg_scale_factors: bool = setting(
        "optimize_emg_scale_factors", kind="boolean", default=True, doc="Optimize EMG scale factors"
    )
    optimize_optimal_fiber_lengths: bool = setting(
        "optimize_optimal_fiber_lengths",
        kind="boolean",
        default=True,
        doc="Optimize optimal fiber length scale factors",
    )
    optimize_tendon_slack_lengths: bool = setting(
        "optimize_tendon_slack_lengths", kind="boolean", default=True, doc="Optimize tendon slack length scale factors"
    )
    max_normalized_muscle_fiber_length: float = setting(
        "max_normalized_muscle_fiber_length",
        kind="number",
        default=1.05,
        check=positive,
        doc="Upper normalized fiber length of the fiber-length terms",
    )
    min_normalized_muscle_fiber_length: float = setting(
        "min_normalized_muscle_fiber_length",
        kind="number",
        default=0.75,
        check=positive,
        doc="Lower normalized fiber length of the fiber-length terms",
    )
    cost_terms: tuple[TermSpec, ...] = setting(
        "RCNLCostTermSet",
        kind="terms",
        term_kind="cost",
        required=True,
        examples=_MTP_TERMS,
        doc="Cost terms of this task",
    )
    source: SourceRef = setting(kind="source", doc="where the task is declared", default=SourceRef())


@attrs.frozen(kw_only=True)
class MuscleTendonPersonalizationSettings(MuscleToolSettings):
    """Validated MTP settings; paths resolved relative to the settings file."""

    collected_emg_channel_muscle_groups: tuple[str, ...] = setting(
        "collected_emg_channel_muscle_groups",
        kind="names",
        required_element=True,
        default=(),
        example="",
        doc="EMG channels used (EMG column names = ForceSet group names)",
    )
    missing_emg_channel_muscle_groups: tuple[str, ...] = setting(
        "missing_emg_channel_muscle_groups",
        kind="names",
        default=(),
        doc="ForceSet groups without EMG (required with synergy extrapolation)",
    )
    synergy_extrapolation: SynergyExtrapolationSettings = setting(
        "MTPSynergyExtrapolation",
        kind="block",
        nested=SynergyExtrapolationSettings,
        required=True,
        doc="Synergy extrapolation",
    )
    tasks: tuple[MtpTask, ...] = setting(
        "MTPTask",
        kind="blocks",
        container="MTPTaskList",
        nested=MtpTask,
        default=(),
        sort_by_index=True,
        enabled_only=True,
        doc="MTP tasks, enabled ones in index order",
    )
    max_iterations: int = setting(
        "max_iterations", kind="integer", default=10000, check=positive, doc="Maximum iterations of the optimizer"
    )
    max_function_evaluations: int = setting(
        "max_function_evaluations",
        kind="integer",
        default=100_000_000,
        check=positive,
        doc="Maximum cost evaluations of the optimizer",
    )
    step_tolerance: float = setting(
        "step_tolerance", kind="number", default=1e-6, check=positive, doc="Step tolerance of the optimizer"
    )
    diff_min_change: float | None = setting(
        "diff_min_change",
        kind="number",
        default=None,
        template="hide",
        doc="Read but ignored by MTP (as in the original)",
    )
    optimality_tolerance: float | None = setting(
        "optimality_tolerance",
        kind="number",
        default=None,
        template="hide",
        doc="Read but ignored by MTP (as in the original)",
    )
    function_tolerance: float | None = setting(
        "function_tolerance",
        kind="number",
        default=None,
        template="hide",
        doc="Read but ignored by MTP (as in the original)",
    )

    OTHER_ELEMENTS: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if values["synergy_extrapolation"].is_enabled and not values["missing_emg_channel_muscle_groups"]:
            raise ctx.error(
                "missing_emg_channel_muscle_groups",
                "<missing_emg_channel_muscle_groups> must name the groups without EMG when synergy extrapolation is enabled",
                "a space-separated list of ForceSet group names",
            )

    @classmethod
    def from_document(cls, doc: SettingsDocument) -> MuscleTendonPersonalizationSettings:
        doc.require_tool(TOOL_ELEMENT)
        return read_block(cls, doc, doc.tool_element)

"""Settings shared by MTP and NCP: data layout, muscle groups, Muscle-Tendon Length Initialization."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import attrs

from nmsm.io.term_spec import TermSpec
from nmsm.io.settings.schema import ReadContext, not_empty, positive, setting

_MTLI_TERM = ({"is_enabled": "true", "type": "passive_joint_moment", "max_allowable_error": "2"},)


@attrs.frozen(kw_only=True)
class MuscleTendonLengthInitializationSettings:
    """``<MuscleTendonLengthInitialization>`` (MTLI, run before MTP or NCP when enabled)."""

    is_enabled: bool = setting(
        "is_enabled", kind="boolean", required=True, example="false", doc="Run muscle-tendon length initialization"
    )
    passive_data_input_directory: Path | None = setting(
        "passive_data_input_directory",
        kind="path",
        path_kind="dir",
        default=None,
        example="passive_data",
        exists_if="is_enabled",
        doc="Folder of passive trials (IKData, IDData, MAData) for passive_joint_moment",
    )
    max_normalized_muscle_fiber_length: float | None = setting(
        "max_normalized_muscle_fiber_length",
        kind="number",
        default=None,
        check=positive,
        example="1",
        doc="Largest normalized fiber length allowed",
    )
    min_normalized_muscle_fiber_length: float | None = setting(
        "min_normalized_muscle_fiber_length",
        kind="number",
        default=None,
        check=positive,
        example="0.6",
        doc="Smallest normalized fiber length allowed",
    )
    optimize_maximum_muscle_stress: bool | None = setting(
        "optimize_maximum_muscle_stress",
        kind="boolean",
        default=None,
        example="true",
        doc="Optimize the maximum muscle stress (required when enabled)",
    )
    optimize_isometric_max_force: bool = setting(
        "optimize_isometric_max_force",
        kind="boolean",
        default=True,
        aliases=("update_maximum_isometric_force",),
        doc="Update the maximum isometric forces (old name: update_maximum_isometric_force)",
    )
    optimize_absolute_length_changes: bool = setting(
        "optimize_absolute_length_changes",
        kind="boolean",
        default=False,
        doc="Optimize absolute length changes instead of scale factors",
    )
    maximum_muscle_stress: float = setting(
        "maximum_muscle_stress", kind="number", default=610000.0, check=positive, doc="Maximum muscle stress (Pa)"
    )
    cost_terms: tuple[TermSpec, ...] = setting(
        "RCNLCostTermSet", kind="terms", term_kind="cost", default=(), examples=_MTLI_TERM, doc="MTLI cost terms"
    )

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if values["is_enabled"] and values["optimize_maximum_muscle_stress"] is None:
            raise ctx.error(
                "optimize_maximum_muscle_stress",
                "<optimize_maximum_muscle_stress> is required when muscle-tendon length initialization is enabled",
                "<optimize_maximum_muscle_stress>true</optimize_maximum_muscle_stress> or false",
            )
        low, high = values["min_normalized_muscle_fiber_length"], values["max_normalized_muscle_fiber_length"]
        if low is not None and high is not None and not low < high:
            raise ctx.error(
                "min_normalized_muscle_fiber_length", f"minimum {low} is not below maximum {high}", "min < max"
            )


@attrs.frozen(kw_only=True)
class MuscleToolSettings:
    """Elements shared by MTP and NCP (``parseMtpNcpSharedInputs``)."""

    settings_file: Path = setting(kind="settings_file", doc="the settings file", default=None)
    results_directory: Path = setting(
        "results_directory",
        kind="path",
        output=True,
        required_element=True,
        empty_is_base=True,
        default=None,
        example="results",
        doc="Results folder (created if missing); empty: the settings file's folder",
    )
    input_model_file: Path = setting(
        "input_model_file",
        kind="path",
        path_kind="file",
        required=True,
        example="model.osim",
        doc="Input model (.osim)",
    )
    input_osimx_file: Path | None = setting(
        "input_osimx_file",
        kind="path",
        path_kind="file",
        required_element=True,
        default=None,
        example="",
        doc="Existing .osimx to extend (may be empty)",
    )
    data_directory: Path = setting(
        "data_directory",
        kind="path",
        path_kind="dir",
        required_element=True,
        empty_is_base=True,
        default=None,
        example="preprocessed",
        doc="Folder with IDData, MAData (and IKData, EMGData); empty: the settings file's folder",
    )
    trial_prefixes: tuple[str, ...] = setting(
        "trial_prefixes", kind="names", default=(), doc="Trials used (empty: every file of IDData)"
    )
    coordinate_list: tuple[str, ...] = setting(
        "coordinate_list",
        kind="names",
        required=True,
        check=not_empty,
        example="knee_angle_r ankle_angle_r",
        doc="Coordinates whose joint moments are tracked; they define the muscles",
    )
    v_max_factor: float = setting(
        "v_max_factor",
        kind="number",
        default=10.0,
        check=positive,
        doc="Maximum shortening velocity (optimal fiber lengths per second)",
    )
    activation_muscle_groups: tuple[str, ...] = setting(
        "activation_muscle_groups",
        kind="names",
        required_element=True,
        default=(),
        example="",
        doc="ForceSet groups whose activations should be alike (may be empty)",
    )
    normalized_fiber_length_muscle_groups: tuple[str, ...] = setting(
        "normalized_fiber_length_muscle_groups",
        kind="names",
        required_element=True,
        default=(),
        example="",
        doc="ForceSet groups whose normalized fiber lengths should be alike (may be empty)",
    )
    muscle_tendon_length_initialization: MuscleTendonLengthInitializationSettings = setting(
        "MuscleTendonLengthInitialization",
        kind="block",
        nested=MuscleTendonLengthInitializationSettings,
        required=True,
        doc="Muscle-tendon length initialization",
    )

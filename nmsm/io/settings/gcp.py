"""Settings of Ground Contact Personalization (``<GroundContactPersonalizationTool>``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import attrs

from nmsm.io.term_spec import SourceRef, TermSpec
from nmsm.errors import InputError
from nmsm.io.settings.document import SettingsDocument
from nmsm.io.settings.schema import ReadContext, at_least_one, non_negative, positive, read_block, setting

TOOL_ELEMENT = "GroundContactPersonalizationTool"

_GCP_TERMS = ({"is_enabled": "true", "type": "vertical_grf", "max_allowable_error": "5"},)

#: design-variable flags of a GCP task, in the original's order
DESIGN_FLAGS = (
    "springConstants",
    "dampingFactor",
    "dynamicFrictionCoefficient",
    "viscousFrictionCoefficient",
    "restingSpringLength",
    "kinematicsBSplineCoefficients",
    "electricalCenterX",
    "electricalCenterY",
    "electricalCenterZ",
    "forcePlateRotation",
)


def _three(value: tuple[str, ...]) -> str | None:
    return None if len(value) in (0, 3) else f"must name 3 columns (X Y Z), got {len(value)}"


@attrs.frozen(kw_only=True)
class ContactSurfaceSettings:
    """One ``<GCPContactSurface>`` (a foot)."""

    name: str | None = setting("name", kind="attribute", default=None, example="Right foot", doc="Surface label")
    is_enabled: bool = setting(
        "is_enabled", kind="boolean", required=True, example="true", doc="Personalize this surface"
    )
    is_left_foot: bool = setting(
        "is_left_foot", kind="boolean", required=True, example="false", doc="Left foot (the foot model is mirrored)"
    )
    start_time: float = setting(
        "start_time", kind="number", required=True, example="0.5", doc="Start of the fitted window (s)"
    )
    end_time: float = setting(
        "end_time", kind="number", required=True, example="1.6", doc="End of the fitted window (s)"
    )
    belt_speed: float = setting(
        "belt_speed", kind="number", required=True, example="1.4", doc="Treadmill belt speed (m/s); 0 overground"
    )
    force_columns: tuple[str, ...] = setting(
        "force_columns",
        kind="names",
        default=(),
        check=_three,
        example="ground_force_2_vx ground_force_2_vy ground_force_2_vz",
        doc="GRF force columns X Y Z",
    )
    moment_columns: tuple[str, ...] = setting(
        "moment_columns",
        kind="names",
        default=(),
        check=_three,
        example="ground_moment_2_mx ground_moment_2_my ground_moment_2_mz",
        doc="GRF moment columns X Y Z",
    )
    electrical_center_columns: tuple[str, ...] = setting(
        "electrical_center_columns",
        kind="names",
        required=True,
        check=_three,
        example="ground_force_2_px ground_force_2_py ground_force_2_pz",
        doc="GRF electrical-center columns X Y Z",
    )
    hindfoot_body: str = setting(
        "hindfoot_body", kind="text", required=True, example="calcn_r", doc="Hindfoot body of the model"
    )
    toe_marker: str = setting("toe_marker", kind="text", required=True, example="R_Toe", doc="Toe marker")
    medial_marker: str = setting(
        "medial_marker", kind="text", required=True, example="R_Toe_Medial", doc="Medial forefoot marker"
    )
    lateral_marker: str = setting(
        "lateral_marker", kind="text", required=True, example="R_Toe_Lateral", doc="Lateral forefoot marker"
    )
    heel_marker: str = setting("heel_marker", kind="text", required=True, example="R_Heel", doc="Heel marker")
    midfoot_superior_marker: str = setting(
        "midfoot_superior_marker",
        kind="text",
        required=True,
        example="R_Midfoot_Superior",
        doc="Midfoot superior marker",
    )
    source: SourceRef = setting(kind="source", doc="where the surface is declared", default=SourceRef())

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        for old in ("toes_coordinate", "toe_coordinate", "toes_joint", "toe_joint"):
            if ctx.child(old) is not None:  # left by the upgrade only when the model could not be read
                raise ctx.error(
                    old,
                    f"<{old}> (NMSM Pipeline 1.0) names the toe joint, and the input model that gives its parent "
                    "body could not be read",
                    "<hindfoot_body> naming the hindfoot body, or a readable <input_model_file>",
                )
        if not values["start_time"] < values["end_time"]:
            raise ctx.error(
                "end_time",
                f"end_time {values['end_time']} is not after start_time {values['start_time']}",
                "start_time < end_time",
            )


def surface_label(surface: ContactSurfaceSettings, index: int) -> str:
    """``<GCPContactSurface> NAME`` (or its 1-based ``index`` among the enabled surfaces)."""
    return f"<GCPContactSurface> {surface.name or index}"


def check_distinct_feet(surfaces: tuple[ContactSurfaceSettings, ...], settings_file: Path | None) -> None:
    """Each enabled surface is another foot: its own hindfoot body and its own force columns
    (two surfaces on one foot, or reading one plate, would fit one set of reactions twice)."""
    first: dict[tuple[str, str | tuple[str, ...]], tuple[int, ContactSurfaceSettings]] = {}
    for index, surface in enumerate(surfaces, start=1):
        for element, key in (("hindfoot_body", surface.hindfoot_body), ("force_columns", surface.force_columns)):
            if not key:
                continue
            seen = first.setdefault((element, key), (index, surface))
            if seen[1] is surface:
                continue
            other = seen[1]
            where = f" (line {other.source.line})" if other.source.line is not None else ""
            shown = key if isinstance(key, str) else " ".join(key)
            raise InputError(f"'{shown}' is also the <{element}> of {surface_label(other, seen[0])}{where}: the "
                             "same foot twice", file=settings_file, line=surface.source.line,
                             element=f"{surface_label(surface, index)}: <{element}>",
                             expected="one <GCPContactSurface> per foot, each with its own hindfoot body and its "
                                      "own force-plate columns")


@attrs.frozen(kw_only=True)
class GcpTask:
    """One ``<GCPTask>``: design-variable flags and cost terms."""

    is_enabled: bool = setting("is_enabled", kind="boolean", required=True, example="true", doc="Run this task")
    index: int | None = setting(
        "index", kind="integer", default=None, example="1", doc="Order of the task (required with more than one task)"
    )
    springConstants: bool = setting("springConstants", kind="boolean", default=False, doc="Optimize spring constants")
    dampingFactor: bool = setting("dampingFactor", kind="boolean", default=False, doc="Optimize the damping factor")
    dynamicFrictionCoefficient: bool = setting(
        "dynamicFrictionCoefficient", kind="boolean", default=False, doc="Optimize the dynamic friction coefficient"
    )
    viscousFrictionCoefficient: bool = setting(
        "viscousFrictionCoefficient", kind="boolean", default=False, doc="Optimize the viscous friction coefficient"
    )
    restingSpringLength: bool = setting(
        "restingSpringLength", kind="boolean", default=False, doc="Optimize the resting spring length"
    )
    kinematicsBSplineCoefficients: bool = setting(
        "kinematicsBSplineCoefficients",
        kind="boolean",
        default=False,
        doc="Optimize the foot kinematics B-spline nodes",
    )
    electricalCenterX: bool = setting(
        "electricalCenterX", kind="boolean", default=False, doc="Optimize the electrical-center x shift"
    )
    electricalCenterY: bool = setting(
        "electricalCenterY", kind="boolean", default=False, doc="Optimize the electrical-center y shift"
    )
    electricalCenterZ: bool = setting(
        "electricalCenterZ", kind="boolean", default=False, doc="Optimize the electrical-center z shift"
    )
    forcePlateRotation: bool = setting(
        "forcePlateRotation", kind="boolean", default=False, doc="Optimize the force-plate rotation"
    )
    neighborStandardDeviation: float = setting(
        "neighborStandardDeviation",
        kind="number",
        default=0.05,
        check=positive,
        doc="Width of the neighbor spring-constant weights (m)",
    )
    cost_terms: tuple[TermSpec, ...] = setting(
        "RCNLCostTermSet",
        kind="terms",
        term_kind="cost",
        required=True,
        examples=_GCP_TERMS,
        doc="Cost terms of this task",
    )
    source: SourceRef = setting(kind="source", doc="where the task is declared", default=SourceRef())

    @property
    def design_flags(self) -> dict[str, bool]:
        """``flag name -> optimized`` in the order of :data:`DESIGN_FLAGS`."""
        return {flag: getattr(self, flag) for flag in DESIGN_FLAGS}


@attrs.frozen(kw_only=True)
class GroundContactPersonalizationSettings:
    """Validated GCP settings; paths resolved relative to the settings file."""

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
    input_directory: Path = setting(
        "input_directory",
        kind="path",
        path_kind="dir",
        empty_is_base=True,
        default=None,
        example="preprocessed",
        doc="Folder the motion and GRF files are relative to; empty: the settings file's folder",
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
        default=None,
        example="",
        doc="Existing .osimx to append the contact surfaces to (optional)",
    )
    input_motion_file: Path = setting(
        "input_motion_file",
        kind="path",
        path_kind="file",
        required=True,
        base="input_directory",
        example="IKData/trial.sto",
        doc="Motion (IK) file, relative to input_directory",
    )
    input_grf_file: Path = setting(
        "input_grf_file",
        kind="path",
        path_kind="file",
        required=True,
        base="input_directory",
        example="GRFData/trial.sto",
        doc="Ground reaction file, relative to input_directory",
    )
    kinematics_filter_cutoff: float = setting(
        "kinematics_filter_cutoff",
        kind="number",
        default=6.0,
        check=positive,
        doc="Cutoff frequency setting the B-spline node count (Hz)",
    )
    initialize_resting_spring_length: bool = setting(
        "initialize_resting_spring_length",
        kind="boolean",
        default=True,
        doc="Initialize the resting spring length from the data",
    )
    grid_width: int = setting(
        "grid_width", kind="integer", default=5, check=at_least_one, doc="Springs across the foot"
    )
    grid_height: int = setting(
        "grid_height", kind="integer", default=15, check=at_least_one, doc="Springs along the foot"
    )
    contact_surfaces: tuple[ContactSurfaceSettings, ...] = setting(
        "GCPContactSurface",
        kind="blocks",
        container="GCPContactSurfaceSet",
        nested=ContactSurfaceSettings,
        required=True,
        enabled_only=True,
        doc="Contact surfaces (enabled ones, in file order)",
    )
    tasks: tuple[GcpTask, ...] = setting(
        "GCPTask",
        kind="blocks",
        container="GCPTaskList",
        nested=GcpTask,
        required=True,
        sort_by_index=True,
        enabled_only=True,
        doc="GCP tasks, enabled ones in index order",
    )
    initial_resting_spring_length: float = setting(
        "initial_resting_spring_length", kind="number", default=0.05, doc="Initial resting spring length (m)"
    )
    initial_spring_constant: float = setting(
        "initial_spring_constant",
        kind="number",
        default=2500.0,
        check=non_negative,
        doc="Initial spring constant (N/m)",
    )
    initial_damping_factor: float = setting(
        "initial_damping_factor", kind="number", default=1e-4, check=non_negative, doc="Initial damping factor (s/m)"
    )
    initial_dynamic_friction_coefficient: float = setting(
        "initial_dynamic_friction_coefficient",
        kind="number",
        default=0.0,
        check=non_negative,
        doc="Initial dynamic friction coefficient",
    )
    initial_viscous_friction_coefficient: float = setting(
        "initial_viscous_friction_coefficient",
        kind="number",
        default=5.0,
        check=non_negative,
        doc="Initial viscous friction coefficient (s/m)",
    )
    latching_velocity: float = setting(
        "latching_velocity",
        kind="number",
        default=0.05,
        check=positive,
        doc="Latching velocity of the friction model (m/s)",
    )
    diff_min_change: float = setting(
        "diff_min_change",
        kind="number",
        default=1e-6,
        check=positive,
        doc="Minimum finite-difference step of the least-squares solver",
    )
    step_tolerance: float = setting(
        "step_tolerance", kind="number", default=1e-6, check=positive, doc="Step tolerance of the least-squares solver"
    )
    optimality_tolerance: float = setting(
        "optimality_tolerance",
        kind="number",
        default=1e-6,
        check=positive,
        doc="Optimality tolerance of the least-squares solver",
    )
    function_tolerance: float = setting(
        "function_tolerance",
        kind="number",
        default=1e-6,
        check=positive,
        doc="Function tolerance of the least-squares solver",
    )
    max_iterations: int = setting(
        "max_iterations",
        kind="integer",
        default=400,
        check=positive,
        doc="Maximum iterations of the least-squares solver",
    )
    max_function_evaluations: int = setting(
        "max_function_evaluations",
        kind="integer",
        default=300000,
        check=positive,
        doc="Maximum cost evaluations of the least-squares solver",
    )

    OTHER_ELEMENTS: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if not values["contact_surfaces"]:
            raise ctx.error(
                "GCPContactSurfaceSet",
                "no enabled <GCPContactSurface>",
                "at least one surface with <is_enabled>true</is_enabled>",
            )
        check_distinct_feet(values["contact_surfaces"], ctx.doc.path)

    @classmethod
    def from_document(cls, doc: SettingsDocument) -> GroundContactPersonalizationSettings:
        doc.require_tool(TOOL_ELEMENT)
        return read_block(cls, doc, doc.tool_element)

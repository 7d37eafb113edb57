"""Settings of Treatment Optimization: Tracking (TO), Verification (VO) and Design (DO).

Controllers: ``<RCNLSynergyController>`` (synergy-driven; needs the osimx synergy groups)
and/or ``<RCNLTorqueController>``; at least one is required. The original looks synergy
controller elements up anywhere in the tool (the tutorial puts ``load_surrogate_model``
next to the controller, not inside it), so each of them is read from the controller
element, else from the tool element.
"""

from __future__ import annotations

import difflib
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import attrs

from nmsm.io.term_spec import SourceRef, TermSpec
from nmsm.io.settings.document import SettingsDocument, elements
from nmsm.io.settings.schema import (
    ReadContext,
    at_least_one,
    increasing_pair,
    non_negative,
    positive,
    read_block,
    setting,
    settings_fields,
)

TOOL_ELEMENTS = ("TrackingOptimizationTool", "VerificationOptimizationTool", "DesignOptimizationTool")
NORMALIZATION_METHODS = ("sum", "magnitude", "none")

_COST_EXAMPLE = (
    {
        "is_enabled": "true",
        "type": "generalized_coordinate_tracking",
        "coordinate_list": "knee_angle_r",
        "max_allowable_error": "0.1",
    },
)
_CONSTRAINT_EXAMPLE = (
    {
        "is_enabled": "true",
        "type": "kinetic_consistency",
        "load_list": "knee_angle_r_moment",
        "max_error": "0.1",
        "min_error": "-0.1",
    },
)


#: controller elements of the tool element
CONTROLLER_ELEMENTS = ("RCNLSynergyController", "RCNLTorqueController", "RCNLMuscleController")


def _controller_near_misses(ctx: ReadContext) -> str:
    """`` (found <X> at line N: did you mean <Y>?)`` for children of the tool element that
    look like a misspelled controller element; empty when there is none."""
    found = []
    for child in elements(ctx.element):
        tag = str(child.tag)
        close = difflib.get_close_matches(tag, CONTROLLER_ELEMENTS, n=1, cutoff=0.75)
        if close:
            found.append(f"found <{tag}> at line {child.sourceline}: did you mean <{close[0]}>?")
        elif "controller" in tag.lower():
            found.append(f"found <{tag}> at line {child.sourceline}, not a controller element")
    return f" ({'; '.join(found)})" if found else ""


@attrs.frozen(kw_only=True)
class TorqueControllerSettings:
    """``<RCNLTorqueController>``: torque actuators on the listed coordinates."""

    coordinate_list: tuple[str, ...] = setting(
        "coordinate_list",
        kind="names",
        required_element=True,
        default=(),
        example="knee_angle_r",
        doc="Torque-controlled coordinates",
    )
    torque_controls_range_scale_factor: float = setting(
        "torque_controls_range_scale_factor",
        kind="number",
        default=1.0,
        check=non_negative,
        doc="Torque-control bounds: range of the experimental ID load times this factor",
    )
    torque_controls_minimum_range: float = setting(
        "torque_controls_minimum_range",
        kind="number",
        default=0.0,
        check=non_negative,
        doc="Smallest torque-control bound range (N m)",
    )


@attrs.frozen(kw_only=True)
class MuscleControllerSettings:
    """``<RCNLMuscleController>``: one activation control per muscle (``individual_muscle``;
    see :mod:`nmsm.controllers.muscle`). Without a surrogate data directory the exact
    path geometry of the model is used."""

    surrogate_model_coordinate_list: tuple[str, ...] = setting(
        "surrogate_model_coordinate_list", kind="names", required=True, example="hip_flexion_r knee_angle_r",
        doc="Coordinates receiving muscle moments (every coordinate the muscles span)")
    muscle_list: tuple[str, ...] = setting("muscle_list", kind="names", default=(), doc="Muscles (default: all)")
    surrogate_model_data_directory: Path | None = setting(
        "surrogate_model_data_directory", kind="path", path_kind="dir", default=None,
        doc="Surrogate data (IKData, MAData); omitted: exact path geometry of the .osim")
    surrogate_model_polynomial_degree: int = setting(
        "surrogate_model_polynomial_degree", kind="integer", default=5, check=at_least_one, doc="Surrogate degree")
    epsilon: float = setting("epsilon", kind="number", default=1e-4, check=positive, doc="Surrogate regularization")
    load_surrogate_model: bool = setting("load_surrogate_model", kind="boolean", default=False, doc="Load surrogate")
    save_surrogate_model: bool = setting("save_surrogate_model", kind="boolean", default=False, doc="Save surrogate")
    surrogate_model_file_name: str = setting(
        "surrogate_model_file_name", kind="text", default="surrogateMuscles.mat",
        doc="Saved surrogate, next to the settings file (kept as JSON: the extension becomes .json)")
    maximum_shortening_velocity_multiplier: float = setting(
        "maximum_shortening_velocity_multiplier", kind="number", default=10.0, check=positive,
        doc="Maximum shortening velocity (optimal fiber lengths per second)")
    minimum_activation: float = setting("minimum_activation", kind="number", default=0.01, check=non_negative,
                                        doc="Lower bound of the activations (and excitations)")
    muscle_force_model: str = setting("muscle_force_model", kind="text", default="nmsm",
                                      choices=("nmsm", "degroote2016"), doc="Hill model: nmsm or degroote2016")
    activation_dynamics: bool = setting(
        "activation_dynamics", kind="boolean", default=False,
        doc="Excitations as controls and activations as states with DeGrooteFregly2016 activation dynamics")
    activation_time_constant: float | None = setting(
        "activation_time_constant", kind="number", default=None, check=positive,
        doc="Activation time constant (s); default: each muscle's value in the .osim, else 0.015")
    deactivation_time_constant: float | None = setting(
        "deactivation_time_constant", kind="number", default=None, check=positive,
        doc="Deactivation time constant (s); default: each muscle's value in the .osim, else 0.060")


@attrs.frozen(kw_only=True)
class SynergyControllerSettings:
    """``<RCNLSynergyController>``: muscles driven by synergies through a surrogate muscle model."""

    surrogate_model_coordinate_list: tuple[str, ...] = setting(
        "surrogate_model_coordinate_list",
        kind="names",
        required=True,
        tool_fallback=True,
        example="knee_angle_r",
        doc="Coordinates of the surrogate muscle model",
    )
    surrogate_model_data_directory: Path = setting(
        "surrogate_model_data_directory",
        kind="path",
        path_kind="dir",
        required=True,
        tool_fallback=True,
        example="surrogateData",
        doc="Sampled poses (IKData) and muscle analyses (MAData) for the surrogate",
    )
    load_surrogate_model: bool = setting(
        "load_surrogate_model", kind="boolean", default=False, tool_fallback=True, doc="Load a saved surrogate model"
    )
    save_surrogate_model: bool = setting(
        "save_surrogate_model", kind="boolean", default=False, tool_fallback=True, doc="Save the fitted surrogate model"
    )
    surrogate_model_file_name: str = setting(
        "surrogate_model_file_name", kind="text", default="surrogateMuscles.mat", tool_fallback=True,
        doc="Saved surrogate, next to the settings file (kept as JSON: the extension becomes .json)",
    )
    epsilon: float = setting(
        "epsilon",
        kind="number",
        default=1e-4,
        check=positive,
        tool_fallback=True,
        doc="Surrogate fitting regularization",
    )
    surrogate_model_polynomial_degree: int = setting(
        "surrogate_model_polynomial_degree",
        kind="integer",
        default=5,
        check=at_least_one,
        tool_fallback=True,
        doc="Polynomial degree of the surrogate",
    )
    perform_latin_hypercube_sampling: bool = setting(
        "perform_latin_hypercube_sampling",
        kind="boolean",
        default=False,
        tool_fallback=True,
        doc="Sample new poses (Latin hypercube)",
    )
    latin_hypercube_range_multiplier: float | None = setting(
        "latin_hypercube_range_multiplier",
        kind="number",
        default=None,
        tool_fallback=True,
        example="1.2",
        doc="Sampling range multiplier (read, unused by the original)",
    )
    latin_hypercube_number_of_points: int | None = setting(
        "latin_hypercube_number_of_points",
        kind="integer",
        default=None,
        tool_fallback=True,
        example="1000",
        doc="Number of sampled poses (read, unused by the original)",
    )
    maximum_shortening_velocity_multiplier: float = setting(
        "maximum_shortening_velocity_multiplier",
        kind="number",
        default=10.0,
        check=positive,
        tool_fallback=True,
        doc="Maximum shortening velocity (optimal fiber lengths per second)",
    )
    optimize_synergy_vectors: bool = setting(
        "optimize_synergy_vectors",
        kind="boolean",
        default=False,
        tool_fallback=True,
        doc="Optimize synergy vectors (not allowed in VO)",
    )
    maximum_allowable_synergy_activation: float = setting(
        "maximum_allowable_synergy_activation",
        kind="number",
        default=10.0,
        check=positive,
        tool_fallback=True,
        doc="Upper bound of synergy activations",
    )
    synergy_vector_normalization_method: str = setting(
        "synergy_vector_normalization_method",
        kind="text",
        default="sum",
        choices=NORMALIZATION_METHODS,
        tool_fallback=True,
        doc="Synergy vector normalization: sum, magnitude or none",
    )
    synergy_vector_normalization_value: float = setting(
        "synergy_vector_normalization_value",
        kind="number",
        default=1.0,
        check=positive,
        tool_fallback=True,
        doc="Value the synergy vectors are normalized to",
    )


@attrs.frozen(kw_only=True)
class ParameterTermSettings:
    """One ``<RCNLParameterTerm>`` of DO: a static design parameter (bounds per value)."""

    type: str = setting("type", kind="text", required=True, example="belt_speed", doc="Parameter type")
    initial_values: tuple[float, ...] = setting(
        "initial_values", kind="numbers", required=True, example="1.4", doc="Initial values"
    )
    lower_bounds: tuple[float, ...] = setting(
        "lower_bounds", kind="numbers", required=True, example="1.0", doc="Lower bounds"
    )
    upper_bounds: tuple[float, ...] = setting(
        "upper_bounds", kind="numbers", required=True, example="1.8", doc="Upper bounds"
    )
    fields: Mapping[str, str] = setting(
        kind="fields", doc="every child element's text (e.g. muscle, is_left_foot)", default=None
    )
    source: SourceRef = setting(kind="source", doc="where the parameter is declared", default=SourceRef())

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        n = len(values["initial_values"])
        for key in ("lower_bounds", "upper_bounds"):
            if len(values[key]) != n:
                raise ctx.error(key, f"{len(values[key])} {key} for {n} initial values", f"{n} values")
        for low, start, high in zip(values["lower_bounds"], values["initial_values"], values["upper_bounds"]):
            if not low <= start <= high:
                raise ctx.error(
                    "initial_values", f"initial value {start} is outside [{low}, {high}]", "lower <= initial <= upper"
                )


@attrs.frozen(kw_only=True)
class TreatmentOptimizationSettings:
    """Elements shared by TO, VO and DO (``parseTreatmentOptimizationInputs``)."""

    tool: str = setting(kind="tool", doc="the tool element", default="")
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
    initial_guess_directory: Path = setting(
        "initial_guess_directory",
        kind="path",
        path_kind="dir",
        required_element=True,
        empty_is_base=True,
        default=None,
        example="preprocessed",
        doc="Initial guess: IKData, IDData, <trial>_states.sto, ...",
    )
    tracked_quantities_directory: Path = setting(
        "tracked_quantities_directory",
        kind="path",
        path_kind="dir",
        required_element=True,
        empty_is_base=True,
        default=None,
        example="preprocessed",
        doc="Tracked data: IKData, IDData, GRFData; empty: the settings file's folder",
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
        doc="Personalized .osimx (contact surfaces, muscles, synergy groups; required for synergy control)",
    )
    optimal_control_solver_settings_file: Path = setting(
        "optimal_control_solver_settings_file",
        kind="path",
        path_kind="file",
        required=True,
        example="solver.xml",
        doc="Optimal control solver settings (nmsm print-xml solver)",
    )
    trial_name: str = setting(
        "trial_name",
        kind="text",
        required=True,
        example="trial",
        doc="Trial whose files are used (exact file name, else unique substring)",
    )
    states_coordinate_list: tuple[str, ...] = setting(
        "states_coordinate_list",
        kind="names",
        required=True,
        example="knee_angle_r",
        doc="Coordinates that are states; the others follow the experimental motion",
    )
    joint_position_range_scale_factor: float = setting(
        "joint_position_range_scale_factor",
        kind="number",
        default=2.0,
        check=non_negative,
        doc="Position bounds: data range times this factor",
    )
    joint_velocity_range_scale_factor: float = setting(
        "joint_velocity_range_scale_factor",
        kind="number",
        default=1.5,
        check=non_negative,
        doc="Velocity bounds: data range times this factor",
    )
    joint_acceleration_range_scale_factor: float = setting(
        "joint_acceleration_range_scale_factor",
        kind="number",
        default=1.0,
        check=non_negative,
        doc="Acceleration bounds: data range times this factor",
    )
    joint_position_minimum_range: float = setting(
        "joint_position_minimum_range",
        kind="number",
        default=0.0,
        check=non_negative,
        doc="Smallest position bound range",
    )
    joint_velocity_minimum_range: float = setting(
        "joint_velocity_minimum_range",
        kind="number",
        default=0.0,
        check=non_negative,
        doc="Smallest velocity bound range",
    )
    joint_acceleration_minimum_range: float = setting(
        "joint_acceleration_minimum_range",
        kind="number",
        default=0.0,
        check=non_negative,
        doc="Smallest acceleration bound range",
    )
    normalize_cost_by_term_type: bool = setting(
        "normalize_cost_by_term_type", kind="boolean", default=False, doc="Average costs per term type before summing"
    )
    experimental_bspline_cutoff_frequency: float = setting(
        "experimental_bspline_cutoff_frequency",
        kind="number",
        default=6.0,
        check=positive,
        doc="Read, unused by the original (Hz)",
    )
    synergy_controller: SynergyControllerSettings | None = setting(
        "RCNLSynergyController",
        kind="block",
        nested=SynergyControllerSettings,
        default=None,
        template="comment",
        doc="Synergy controller (needs input_osimx_file with synergy groups)",
    )
    torque_controller: TorqueControllerSettings | None = setting(
        "RCNLTorqueController", kind="block", nested=TorqueControllerSettings, default=None, doc="Torque controller"
    )
    muscle_controller: MuscleControllerSettings | None = setting(
        "RCNLMuscleController", kind="block", nested=MuscleControllerSettings, default=None, template="comment",
        doc="Individual muscle activation controller",
    )
    cost_terms: tuple[TermSpec, ...] = setting(
        "RCNLCostTermSet", kind="terms", term_kind="cost", required=True, examples=_COST_EXAMPLE, doc="Cost terms"
    )
    constraint_terms: tuple[TermSpec, ...] = setting(
        "RCNLConstraintTermSet",
        kind="terms",
        term_kind="constraint",
        required=True,
        examples=_CONSTRAINT_EXAMPLE,
        doc="Constraint terms (may be empty)",
    )

    TOOL_ELEMENT: ClassVar[str] = ""
    #: synergy-controller elements may sit at the tool level (see module docstring)
    OTHER_ELEMENTS: ClassVar[tuple[str, ...]] = tuple(
        spec.element for _, spec in settings_fields(SynergyControllerSettings) if spec.tool_fallback
    )

    @property
    def tool_code(self) -> str:
        return {"TrackingOptimizationTool": "TO", "VerificationOptimizationTool": "VO", "DesignOptimizationTool": "DO"}[
            self.tool
        ]

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if (values["synergy_controller"] is None and values["torque_controller"] is None
                and values.get("muscle_controller") is None):
            raise ctx.doc.error(
                ctx.element,
                "no controller" + _controller_near_misses(ctx),
                element="<RCNLSynergyController>/<RCNLTorqueController>",
                expected="an <RCNLSynergyController> and/or an <RCNLTorqueController>",
            )
        if values["synergy_controller"] is not None and values["input_osimx_file"] is None:
            raise ctx.error(
                "input_osimx_file",
                "a synergy controller needs <input_osimx_file> (its RCNLSynergySet names the synergy groups)",
                "the .osimx written by NCP",
            )

    @classmethod
    def from_document(cls, doc: SettingsDocument) -> TreatmentOptimizationSettings:
        doc.require_tool(cls.TOOL_ELEMENT)
        return read_block(cls, doc, doc.tool_element)


@attrs.frozen(kw_only=True)
class TrackingOptimizationSettings(TreatmentOptimizationSettings):
    """``<TrackingOptimizationTool>``."""

    TOOL_ELEMENT: ClassVar[str] = "TrackingOptimizationTool"


@attrs.frozen(kw_only=True)
class VerificationOptimizationSettings(TreatmentOptimizationSettings):
    """``<VerificationOptimizationTool>``: fixed synergy vectors."""

    TOOL_ELEMENT: ClassVar[str] = "VerificationOptimizationTool"

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        super().validate(values, ctx)
        synergy = values["synergy_controller"]
        if synergy is not None and synergy.optimize_synergy_vectors:
            raise ctx.error(
                "RCNLSynergyController",
                "Verification Optimization keeps synergy vectors fixed; <optimize_synergy_vectors> must be false",
                "<optimize_synergy_vectors>false</optimize_synergy_vectors>",
            )


@attrs.frozen(kw_only=True)
class DesignOptimizationSettings(TreatmentOptimizationSettings):
    """``<DesignOptimizationTool>``: free final time, model functions, static parameters."""

    TOOL_ELEMENT: ClassVar[str] = "DesignOptimizationTool"

    final_time_range: tuple[float, float] | None = setting(
        "final_time_range",
        kind="numbers",
        count=2,
        default=None,
        check=increasing_pair,
        example="0.9 1.3",
        doc="Free final time between these bounds (s, 0 < lower < upper); fixed final time if absent",
    )
    model_functions: tuple[str, ...] = setting(
        "model_functions", kind="names", default=(), doc="Functions applied to the model at each evaluation"
    )
    parameter_terms: tuple[ParameterTermSettings, ...] = setting(
        "RCNLParameterTerm",
        kind="blocks",
        container="RCNLParameterTermSet",
        nested=ParameterTermSettings,
        default=(),
        doc="Static design parameters",
    )

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        super().validate(values, ctx)
        bounds = values.get("final_time_range")
        if bounds is not None and not 0 < bounds[0] <= bounds[1]:
            raise ctx.error(
                "final_time_range",
                f"final time bounds {bounds[0]:g} {bounds[1]:g}: a final time (the movement's duration) must be > 0",
                "0 < lower <= upper (s)",
            )

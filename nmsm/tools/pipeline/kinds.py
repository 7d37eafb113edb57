"""The kinds of stage a pipeline can hold, in the order they may run.

A stage kind is identified by its settings tool element. It declares:

* ``order``: stages must appear in non-decreasing order (a later stage consumes what
  earlier ones produce: JMP changes the model every following stage uses, so JMP after
  MTP is impossible);
* ``requires`` / ``uses``: artifacts (:mod:`nmsm.tools.pipeline.artifacts`) it must have /
  takes when available;
* ``wires``: which settings element receives which artifact (the runner rewrites it), and
  ``hook`` for wiring that depends on the settings (the treatment's initial guess);
* ``produces`` and :attr:`StageKind.outputs`: where its outputs are found after a run;
* ``run``: ``"module:function"`` called as ``function(settings_file, **options)``;
* ``validate``: optional ``"module:function"`` called with the parsed settings before
  anything runs (:mod:`nmsm.tools.pipeline.validation`: term types, solver settings), beyond
  what the settings class itself checks;
* ``bind``: optional ``"module:function"`` that ``--check`` calls with the parsed settings to
  bind the stage's cost and constraint terms to its model and data without solving
  (:func:`nmsm.tools.pipeline.validation.bind_treatment`); ``has_terms``: the stage has terms
  (without ``bind``, ``--check`` says they are bound when the stage runs).

================  ================================  =====  =========================================
code              tool element                      order  produces
================  ================================  =====  =========================================
``jmp``           JointModelPersonalizationTool        10  model
``analysis``      ModelAnalysisTool                    20  motion_data
``preprocess``    DataPreprocessingTool                30  data_directory
``mtp``           MuscleTendonPersonalizationTool      40  osimx, mtp_results
``ncp``           NeuralControlPersonalizationTool     50  osimx, ncp_results
``gcp``           GroundContactPersonalizationTool     60  osimx, gcp_results
``surrogate``     SurrogateDataTool                    70  surrogate_data
``to``            TrackingOptimizationTool             80  treatment_results
``vo``            VerificationOptimizationTool         90  treatment_results
``do``            DesignOptimizationTool              100  treatment_results
================  ================================  =====  =========================================

Tests and plugins may add kinds with :func:`register_stage_kind`.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import attrs

from nmsm.errors import InputError


@attrs.frozen
class Wire:
    """Artifact ``artifact`` goes into path element ``key`` (below the tool element).

    ``only_if_present``: rewire only when the settings already have the element's parent
    block (the synergy controller's data folder in a torque-driven settings file has none).
    """

    artifact: str
    key: str
    only_if_present: bool = False


OutputsFunction = Callable[[Any, Path], dict[str, Path]]


@attrs.frozen
class StageKind:
    """A kind of stage (see module docstring)."""

    code: str
    label: str
    tool_element: str
    order: int
    settings_class: str | type  #: the declarative settings class, or "module:Class"
    run: str | Callable[..., Any]  #: function (settings_file, **options), or "module:function"
    outputs: str | OutputsFunction  #: function (StageSettings, results folder) -> {artifact: path}
    requires: tuple[str, ...] = ()
    uses: tuple[str, ...] = ()
    produces: tuple[str, ...] = ()
    wires: tuple[Wire, ...] = ()
    hook: str | Callable[..., Any] | None = None  #: (StageSettings, Artifacts, kept keys) -> {key: source}
    #: the elements ``hook`` may rewire (with the wires' keys, the names ``keep_settings_inputs`` accepts)
    hook_keys: tuple[str, ...] = ()
    run_options: Mapping[str, Any] = attrs.field(factory=dict)
    validate: str | Callable[[Any], None] | None = None  #: checks of the parsed settings (module docstring)
    bind: str | Callable[[Any], None] | None = None  #: binds the parsed settings' terms (module docstring)
    has_terms: bool = False  #: the settings hold cost or constraint terms

    def load_settings_class(self) -> type:
        return _load(self.settings_class)

    def load_run(self) -> Callable[..., Any]:
        return _load(self.run)

    def load_outputs(self) -> OutputsFunction:
        return _load(self.outputs)

    def load_validate(self) -> Callable[[Any], None] | None:
        return None if self.validate is None else _load(self.validate)

    def load_bind(self) -> Callable[[Any], None] | None:
        return None if self.bind is None else _load(self.bind)

    def load_hook(self) -> Callable[..., Any] | None:
        return None if self.hook is None else _load(self.hook)

    def wires_for(self, artifact: str) -> tuple[Wire, ...]:
        return tuple(w for w in self.wires if w.artifact == artifact)

    def rewired_keys(self) -> tuple[str, ...] | None:
        """The elements the runner may rewire (``None``: not known, a hook without ``hook_keys``)."""
        if self.hook is not None and not self.hook_keys:
            return None
        return (*(w.key for w in self.wires), *self.hook_keys)


def _load(target: Any) -> Any:
    if not isinstance(target, str):
        return target
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


_PERSONALIZATION_WIRES = (
    Wire("model", "input_model_file"),
    Wire("osimx", "input_osimx_file"),
    Wire("data_directory", "data_directory"),
)
_TREATMENT_SETTINGS = "nmsm.io.settings.treatment:"
_OUT = "nmsm.tools.pipeline.outputs:"
_CHECK = "nmsm.tools.pipeline.validation:"

_BUILT_IN = (
    StageKind("jmp", "Joint Model Personalization", "JointModelPersonalizationTool", 10,
              "nmsm.io.settings.jmp:JointModelPersonalizationSettings", "nmsm.tools.jmp.run:run_settings",
              _OUT + "jmp_outputs", requires=("model",), produces=("model",),
              wires=(Wire("model", "input_model_file"),), run_options={"quiet": True}, has_terms=True),
    StageKind("analysis", "IK, ID and muscle analysis on the current model", "ModelAnalysisTool", 20,
              "nmsm.tools.pipeline.analysis_settings:ModelAnalysisSettings",
              "nmsm.tools.pipeline.analysis:run_settings", _OUT + "analysis_outputs",
              requires=("model",), produces=("motion_data",), wires=(Wire("model", "input_model_file"),)),
    StageKind("preprocess", "Data preprocessing", "DataPreprocessingTool", 30,
              "nmsm.tools.pipeline.preprocess_settings:DataPreprocessingSettings",
              "nmsm.tools.pipeline.preprocess_stage:run_settings", _OUT + "preprocess_outputs",
              requires=("model", "motion_data"), produces=("data_directory",),
              wires=(Wire("model", "input_model_file"), Wire("motion_data", "motion_data_directory"))),
    StageKind("mtp", "Muscle-Tendon Personalization", "MuscleTendonPersonalizationTool", 40,
              "nmsm.io.settings.mtp:MuscleTendonPersonalizationSettings", "nmsm.tools.mtp.run:run_settings",
              _OUT + "mtp_outputs", requires=("model", "data_directory"), uses=("osimx",),
              produces=("osimx", "mtp_results"), wires=_PERSONALIZATION_WIRES, validate=_CHECK + "mtp",
              has_terms=True, run_options={"keep_finished_on_stop": False}),
    StageKind("ncp", "Neural Control Personalization", "NeuralControlPersonalizationTool", 50,
              "nmsm.io.settings.ncp:NeuralControlPersonalizationSettings", "nmsm.tools.ncp.run:run_settings",
              _OUT + "ncp_outputs", requires=("model", "data_directory"), uses=("osimx", "mtp_results"),
              produces=("osimx", "ncp_results"),
              wires=(*_PERSONALIZATION_WIRES, Wire("mtp_results", "mtp_results_directory")),
              run_options={"print_level": 0}, validate=_CHECK + "ncp", has_terms=True),
    StageKind("gcp", "Ground Contact Personalization", "GroundContactPersonalizationTool", 60,
              "nmsm.io.settings.gcp:GroundContactPersonalizationSettings", "nmsm.tools.gcp.run:run_settings",
              _OUT + "gcp_outputs", requires=("model", "data_directory"), uses=("osimx",),
              produces=("osimx", "gcp_results"),
              wires=(Wire("model", "input_model_file"), Wire("osimx", "input_osimx_file"),
                     Wire("data_directory", "input_directory")), validate=_CHECK + "gcp", has_terms=True,
              run_options={"keep_finished_on_stop": False}),
    StageKind("surrogate", "Surrogate muscle-geometry data", "SurrogateDataTool", 70,
              "nmsm.tools.pipeline.surrogate_settings:SurrogateDataSettings",
              "nmsm.tools.pipeline.surrogate_stage:run_settings", _OUT + "surrogate_outputs",
              requires=("model", "data_directory"), produces=("surrogate_data",),
              wires=(Wire("model", "input_model_file"), Wire("data_directory", "data_directory"))),
    StageKind("to", "Tracking Optimization", "TrackingOptimizationTool", 80,
              _TREATMENT_SETTINGS + "TrackingOptimizationSettings", "nmsm.tools.treatment.run:run_settings",
              _OUT + "treatment_outputs", requires=("model", "data_directory"),
              uses=("osimx", "ncp_results", "surrogate_data"), produces=("treatment_results",),
              wires=(Wire("model", "input_model_file"), Wire("osimx", "input_osimx_file"),
                     Wire("data_directory", "tracked_quantities_directory"),
                     Wire("surrogate_data", "RCNLSynergyController/surrogate_model_data_directory", True)),
              hook="nmsm.tools.pipeline.wiring:tracking_initial_guess", hook_keys=("initial_guess_directory",),
              run_options={"print_level": 0},
              validate=_CHECK + "treatment", bind=_CHECK + "bind_treatment",
              has_terms=True),
    StageKind("vo", "Verification Optimization", "VerificationOptimizationTool", 90,
              _TREATMENT_SETTINGS + "VerificationOptimizationSettings", "nmsm.tools.treatment.run:run_settings",
              _OUT + "treatment_outputs", requires=("model", "treatment_results"),
              uses=("osimx", "surrogate_data"), produces=("treatment_results",),
              wires=(Wire("model", "input_model_file"), Wire("osimx", "input_osimx_file"),
                     Wire("treatment_results", "initial_guess_directory"),
                     Wire("treatment_results", "tracked_quantities_directory"),
                     Wire("surrogate_data", "RCNLSynergyController/surrogate_model_data_directory", True)),
              run_options={"print_level": 0}, validate=_CHECK + "treatment", bind=_CHECK + "bind_treatment",
              has_terms=True),
    StageKind("do", "Design Optimization", "DesignOptimizationTool", 100,
              _TREATMENT_SETTINGS + "DesignOptimizationSettings", "nmsm.tools.treatment.run:run_settings",
              _OUT + "treatment_outputs", requires=("model", "treatment_results"),
              uses=("osimx", "surrogate_data"), produces=("treatment_results",),
              wires=(Wire("model", "input_model_file"), Wire("osimx", "input_osimx_file"),
                     Wire("treatment_results", "initial_guess_directory"),
                     Wire("treatment_results", "tracked_quantities_directory"),
                     Wire("surrogate_data", "RCNLSynergyController/surrogate_model_data_directory", True)),
              run_options={"print_level": 0}, validate=_CHECK + "treatment", bind=_CHECK + "bind_treatment",
              has_terms=True),
)

_REGISTRY: dict[str, StageKind] = {kind.tool_element: kind for kind in _BUILT_IN}


def register_stage_kind(kind: StageKind) -> None:
    """Add a stage kind (tests, plugins); its tool element and code must be new."""
    if kind.tool_element in _REGISTRY or any(k.code == kind.code for k in _REGISTRY.values()):
        raise ValueError(f"stage kind '{kind.code}' (<{kind.tool_element}>) is already registered")
    _REGISTRY[kind.tool_element] = kind


def unregister_stage_kind(tool_element: str) -> None:
    """Remove a kind added with :func:`register_stage_kind`."""
    if any(k.tool_element == tool_element for k in _BUILT_IN):
        raise ValueError(f"<{tool_element}> is a built-in stage kind")
    _REGISTRY.pop(tool_element, None)


def stage_kinds() -> dict[str, StageKind]:
    """Tool element -> kind, in pipeline order."""
    return dict(sorted(_REGISTRY.items(), key=lambda item: item[1].order))


def kind_for_element(tool_element: str, *, file: Path | None = None, line: int | None = None) -> StageKind:
    """The kind of a settings tool element; :class:`InputError` listing the known ones."""
    kind = _REGISTRY.get(tool_element)
    if kind is None:
        raise InputError(f"<{tool_element}> is not a pipeline stage", file=file, line=line,
                         element=f"<{tool_element}>",
                         expected="one of " + ", ".join(f"<{t}>" for t in stage_kinds()))
    return kind


def order_text() -> str:
    """The pipeline order, for messages: ``JMP -> analysis -> ...``."""
    return " -> ".join(k.code for k in stage_kinds().values())

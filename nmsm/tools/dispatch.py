"""``nmsm run SETTINGS.xml``: find the tool element and hand the file to that tool."""

from __future__ import annotations

import importlib
import warnings
from pathlib import Path
from typing import Any

from nmsm.errors import InputError

#: settings tool element -> "module:function" taking (settings_path, **options)
TOOL_RUNNERS: dict[str, str] = {
    "JointModelPersonalizationTool": "nmsm.tools.jmp.run:run_settings",
    "MuscleTendonPersonalizationTool": "nmsm.tools.mtp.run:run_settings",
    "NeuralControlPersonalizationTool": "nmsm.tools.ncp.run:run_settings",
    "GroundContactPersonalizationTool": "nmsm.tools.gcp.run:run_settings",
    "TrackingOptimizationTool": "nmsm.tools.treatment.run:run_settings",
    "VerificationOptimizationTool": "nmsm.tools.treatment.run:run_settings",
    "DesignOptimizationTool": "nmsm.tools.treatment.run:run_settings",
    # the pipeline's own stages and pipeline files (nmsm.tools.pipeline.native.NATIVE_RUNNERS)
    "PipelineTool": "nmsm.tools.pipeline.runner:run_pipeline_file",
    "ModelAnalysisTool": "nmsm.tools.pipeline.analysis:run_settings",
    "DataPreprocessingTool": "nmsm.tools.pipeline.preprocess_stage:run_settings",
    "SurrogateDataTool": "nmsm.tools.pipeline.surrogate_stage:run_settings",
}


#: tools whose runs take ``guess_directory`` (``nmsm run --start-from``): the treatment tools
TREATMENT_TOOLS: frozenset[str] = frozenset(
    tag for tag, target in TOOL_RUNNERS.items() if target == TOOL_RUNNERS["TrackingOptimizationTool"])

#: tools that solve an optimization: the ones ``accept_unconverged`` applies to
SOLVING_TOOLS: frozenset[str] = frozenset({
    "JointModelPersonalizationTool", "MuscleTendonPersonalizationTool", "NeuralControlPersonalizationTool",
    "GroundContactPersonalizationTool", "TrackingOptimizationTool", "VerificationOptimizationTool",
    "DesignOptimizationTool"})


def tool_element_name(settings_file: str | Path) -> str:
    """The tool element of a settings file (old schemas upgraded first)."""
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.tools.pipeline.native import native_tool_element

    native = native_tool_element(settings_file)  # the pipeline's own stages and pipeline files
    if native is not None:
        return native

    with warnings.catch_warnings():  # the tool's own reading reports the upgrade, once
        warnings.simplefilter("ignore")
        doc = read_settings_document(settings_file)
    return doc.tool_element.tag


def run_settings_file(settings_file: str | Path, **options: Any) -> Any:
    tag = tool_element_name(settings_file)
    target = TOOL_RUNNERS.get(tag)
    if target is None:
        if tag == "OptimalControlSolverSettings":
            raise InputError(
                "<OptimalControlSolverSettings> is the solver settings of a treatment optimization, not a tool to run",
                file=settings_file,
                expected="a Tracking, Verification or Design Optimization settings file naming this file in its "
                "<optimal_control_solver_settings_file>: run that file",
            )
        raise InputError(
            f"unknown tool element <{tag}>",
            file=settings_file,
            expected="one of " + ", ".join(f"<{t}>" for t in TOOL_RUNNERS),
        )
    if options.get("guess_directory") is not None and tag not in TREATMENT_TOOLS:
        raise InputError(f"--start-from is for treatment optimization settings, not <{tag}>", file=settings_file,
                         expected="a <" + ">, <".join(sorted(TREATMENT_TOOLS)) + "> settings file")
    if not options.get("accept_unconverged", True) or (tag not in SOLVING_TOOLS and tag != "PipelineTool"):
        options.pop("accept_unconverged", None)  # a tool without a solve has nothing to accept
    module_name, func_name = target.split(":")
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        raise InputError(f"tool <{tag}> is not available in this version of nmsm ({exc})", file=settings_file) from exc
    return getattr(module, func_name)(Path(settings_file), **options)

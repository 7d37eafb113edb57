"""Settings of Joint Model Personalization (``<JointModelPersonalizationTool>``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar

import attrs

from nmsm.io.term_spec import SourceRef
from nmsm.io.paths import normalize_separators
from nmsm.io.settings.document import SettingsDocument
from nmsm.io.settings.schema import ReadContext, increasing_pair, positive, read_block, setting

TOOL_ELEMENT = "JointModelPersonalizationTool"


@attrs.frozen(kw_only=True)
class JmpFrame:
    """Which offset-frame parameters of a joint are optimized, and their search bounds."""

    translation: tuple[bool, bool, bool] = setting(
        "translation",
        kind="booleans",
        count=3,
        required=True,
        example="false false false",
        doc="Three true/false: optimize the frame's x y z translation",
    )
    orientation: tuple[bool, bool, bool] = setting(
        "orientation",
        kind="booleans",
        count=3,
        required=True,
        example="false false false",
        doc="Three true/false: optimize the frame's x y z orientation (body-fixed XYZ angles)",
    )
    translation_bounds: float | None = setting(
        "translation_bounds",
        kind="number",
        default=None,
        check=positive,
        example="0.05",
        doc="Translations move at most this far from their initial value (m)",
    )
    orientation_bounds: float | None = setting(
        "orientation_bounds",
        kind="number",
        default=None,
        check=positive,
        example="0.5",
        doc="Orientations move at most this far from their initial value (rad)",
    )


@attrs.frozen(kw_only=True)
class JmpJoint:
    """A joint whose parent and child offset frames are personalized."""

    name: str = setting("name", kind="attribute", required=True, example="knee_r", doc="Joint name in the model")
    parent_frame_transformation: JmpFrame = setting(
        "parent_frame_transformation", kind="block", nested=JmpFrame, required=True, doc="Joint parent frame"
    )
    child_frame_transformation: JmpFrame = setting(
        "child_frame_transformation", kind="block", nested=JmpFrame, required=True, doc="Joint child frame"
    )
    source: SourceRef = setting(kind="source", doc="where the joint is declared", default=SourceRef())


@attrs.frozen(kw_only=True)
class JmpBody:
    """A body that is scaled and/or whose markers move."""

    name: str = setting("name", kind="attribute", required=True, example="pelvis", doc="Body name in the model")
    scale_body: bool = setting(
        "scale_body", kind="boolean", required=True, example="true", doc="Scale the body (one factor)"
    )
    move_markers: tuple[bool, bool, bool] = setting(
        "move_markers",
        kind="booleans",
        count=3,
        default=(False, False, False),
        doc="Three true/false: the body's markers are free to move along x y z",
    )
    source: SourceRef = setting(kind="source", doc="where the body is declared", default=SourceRef())


@attrs.frozen(kw_only=True)
class JmpTask:
    """One optimization of JMP (tasks run in ``index`` order; disabled ones are dropped)."""

    name: str | None = setting("name", kind="attribute", default=None, example="Right Knee", doc="Task label")
    is_enabled: bool = setting("is_enabled", kind="boolean", required=True, example="true", doc="Run this task")
    index: int | None = setting(
        "index", kind="integer", default=None, example="1", doc="Order of the task (required with more than one task)"
    )
    marker_file_name: Path = setting(
        "marker_file_name",
        kind="path",
        path_kind="file",
        required=True,
        example="markers.trc",
        doc="Marker file (.trc) of this task",
    )
    marker_names: tuple[str, ...] = setting(
        "marker_names",
        kind="names",
        default=(),
        doc="Markers used (empty: the markers on the bodies the task moves)",
    )
    time_range: tuple[float, float] | None = setting(
        "time_range",
        kind="numbers",
        count=2,
        default=None,
        check=increasing_pair,
        example="0 1",
        doc="Start and end time of the marker data used (s); all frames if absent",
    )
    anatomical_markers: bool = setting(
        "anatomical_markers", kind="boolean", default=False, doc="Markers scale with their body"
    )
    free_markers: tuple[str, ...] = setting(
        "free_markers", kind="names", default=(), doc="Markers free to move along x y z"
    )
    joints: tuple[JmpJoint, ...] = setting(
        "JMPJoint",
        kind="blocks",
        container="JMPJointSet",
        nested=JmpJoint,
        default=(),
        doc="Joints personalized in this task",
    )
    bodies: tuple[JmpBody, ...] = setting(
        "JMPBody", kind="blocks", container="JMPBodySet", nested=JmpBody, default=(), doc="Bodies scaled in this task"
    )
    source: SourceRef = setting(kind="source", doc="where the task is declared", default=SourceRef())

    def first_bound(self, which: str) -> float | None:
        """``translation_bounds`` / ``orientation_bounds`` as the original finds it: the first in document order.

        The original looks the bound up once per task with a depth-first search, so the
        first joint's parent-frame value applies to every frame of the task.
        """
        for joint in self.joints:
            for frame in (joint.parent_frame_transformation, joint.child_frame_transformation):
                value = getattr(frame, which)
                if value is not None:
                    return value
        return None


@attrs.frozen(kw_only=True)
class JointModelPersonalizationSettings:
    """Validated JMP settings; paths resolved relative to the settings file."""

    settings_file: Path = setting(kind="settings_file", doc="the settings file", default=None)
    results_directory: Path = setting(
        "results_directory",
        kind="path",
        output=True,
        empty_is_base=True,
        default=None,
        doc="Folder for the output model (created if missing); empty: the settings file's folder",
    )
    input_directory: str | None = setting(
        "input_directory",
        kind="text",
        default=None,
        template="hide",
        doc="Present in the reference XML; not read (as in the original)",
    )
    input_model_file: Path = setting(
        "input_model_file",
        kind="path",
        path_kind="file",
        required=True,
        example="model.osim",
        doc="Input model (.osim)",
    )
    output_model_file: str = setting(
        "output_model_file",
        kind="text",
        required=True,
        example="model_jmp.osim",
        doc="Output model name; written to results_directory under this file name",
    )
    allowable_error: float = setting(
        "allowable_error",
        kind="number",
        required=True,
        check=positive,
        example="0.01",
        doc="Marker error that counts as acceptable (model units, 0.01 = 1 cm); residuals are divided by it",
    )
    tasks: tuple[JmpTask, ...] = setting(
        "JMPTask",
        kind="blocks",
        container="JMPTaskList",
        nested=JmpTask,
        required=True,
        sort_by_index=True,
        enabled_only=True,
        doc="Tasks (one optimization each), enabled ones in index order",
    )
    accuracy: float | None = setting(
        "accuracy",
        kind="number",
        default=None,
        check=positive,
        example="1e-06",
        doc="Inverse-kinematics solver accuracy (OpenSim's default if absent)",
    )
    diff_min_change: float = setting(
        "diff_min_change",
        kind="number",
        default=1e-4,
        check=positive,
        doc="Minimum finite-difference step of the least-squares solver",
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
    step_tolerance: float = setting(
        "step_tolerance", kind="number", default=1e-6, check=positive, doc="Step tolerance of the least-squares solver"
    )
    max_function_evaluations: int = setting(
        "max_function_evaluations",
        kind="integer",
        default=3000,
        check=positive,
        doc="Maximum cost evaluations of the least-squares solver",
    )

    #: known elements that JMP does not read (reference XML)
    OTHER_ELEMENTS: ClassVar[tuple[str, ...]] = ("max_iterations",)

    @property
    def output_model_path(self) -> Path:
        """``results_directory / basename(output_model_file)``."""
        return self.results_directory / Path(normalize_separators(self.output_model_file)).name

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if not values["tasks"]:
            raise ctx.error(
                "JMPTaskList", "no enabled <JMPTask>", "at least one task with <is_enabled>true</is_enabled>"
            )
        for task in values["tasks"]:
            if not task.joints and not task.bodies and not task.free_markers:
                raise ctx.doc.error(
                    ctx.element,
                    f"task '{task.name or task.index}' (line {task.source.line}) personalizes nothing",
                    element="<JMPTask>",
                    expected="a <JMPJointSet>, <JMPBodySet> or <free_markers> in every enabled task",
                )

    @classmethod
    def from_document(cls, doc: SettingsDocument) -> JointModelPersonalizationSettings:
        doc.require_tool(TOOL_ELEMENT)
        return read_block(cls, doc, doc.tool_element)

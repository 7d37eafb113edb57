"""JMP design variables of one task: which model quantities move, their bounds, the markers used.

Order (the original's): joint offset-frame parameters flagged ``true`` (joints in task order;
parent then child frame; translation then orientation; x y z), then body scale factors
(``scale_body``), then marker location components (``move_markers`` axes of the markers of
that body used by the task, ``free_markers`` all axes).

Bounds (the original's rule): when any joint bound of the task is given and non-zero,
joint parameters move within ``initial +- bound`` of *their own frame* (the original applies
the first bound found in the task to every frame; every shared settings file uses one value
per task, and a frame flagged without a bound gets a warning and is frozen), while scale
factors and marker locations are free (scale factors kept > 0.01); otherwise every variable
lies within ``initial +- 10``. Units: m, rad; scale factors relative to the model the task
starts from (1 = unchanged).

Markers used: ``<marker_names>`` when given; else the markers (present in the marker file)
on the parent and child bodies of the task's joints, on its scaled bodies and bodies with
moving markers, plus its free markers.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.io.settings.jmp import JmpFrame, JmpTask
from nmsm.model.components import Model
from nmsm.model.parameters import ModelParameters

_AXES = "xyz"
#: bound of every variable when the task gives no joint bound (the original's)
DEFAULT_BOUND = 10.0
#: smallest scale factor allowed
MIN_SCALE = 0.01


@attrs.frozen
class DesignVariable:
    """One optimized quantity: ``kind`` is ``translation``/``orientation`` (of the offset frame
    ``target``), ``scale`` (body ``target``) or ``marker`` (marker ``target``); ``label`` is
    human readable; ``joint`` the JMP joint it belongs to (frame parameters)."""

    kind: str
    target: str
    component: int
    label: str
    initial: float
    lower: float
    upper: float
    joint: str | None = None


@attrs.frozen(eq=False)
class TaskDesign:
    """Design of one task: ``parameters`` (CasADi symbols, in :attr:`variables` order),
    ``variables``, ``marker_names`` used and ``unscaled_marker_bodies`` (scaled bodies whose
    markers stay put). Scaled bodies keep their mass, their inertia scales by ``s**2``
    (``Model.scale(preserveMassDist=true)`` as the original calls it)."""

    parameters: ModelParameters
    variables: tuple[DesignVariable, ...]
    marker_names: tuple[str, ...]
    unscaled_marker_bodies: frozenset[str]

    @property
    def lower(self) -> np.ndarray:
        return np.array([v.lower for v in self.variables], dtype=float)

    @property
    def upper(self) -> np.ndarray:
        return np.array([v.upper for v in self.variables], dtype=float)

    @property
    def initial(self) -> np.ndarray:
        return np.array([v.initial for v in self.variables], dtype=float)


def _task_label(task: JmpTask) -> str:
    return f"task '{task.name or task.index or 1}'"


def _error(task: JmpTask, settings_file: str | None, message: str, element: str, expected: str,
           line: int | None = None) -> InputError:
    return InputError(f"{_task_label(task)}: {message}", file=settings_file,
                      line=line if line is not None else task.source.line, element=element, expected=expected)


def _has_bounds(task: JmpTask) -> bool:
    for joint in task.joints:
        for frame in (joint.parent_frame_transformation, joint.child_frame_transformation):
            for value in (frame.translation_bounds, frame.orientation_bounds):
                if value:
                    return True
    return False


def check_names(model: Model, task: JmpTask, marker_file_names: Sequence[str], settings_file: str | None) -> None:
    """Every joint, body and marker the task names exists (in the model; markers also in the
    marker file), else :class:`InputError` naming the settings file and element."""
    joints = [j.name for j in model.joints]
    seen: set[str] = set()
    for joint in task.joints:
        if joint.name in seen:
            raise _error(task, settings_file, f"joint '{joint.name}' is listed twice", f'<JMPJoint name="{joint.name}">',
                         "each joint once per task (flag all its parameters in one <JMPJoint>)", joint.source.line)
        seen.add(joint.name)
        if joint.name not in joints:
            close = close_matches(joint.name, joints)
            raise _error(task, settings_file, f"joint '{joint.name}' is not in the model {model.file}"
                         + (f"; close matches: {', '.join(close)}" if close else ""),
                         f'<JMPJoint name="{joint.name}">', "a joint of the model", joint.source.line)
    seen_bodies: set[str] = set()
    for body in task.bodies:
        if body.name in seen_bodies:  # its scale would be declared twice (a ValueError traceback)
            raise _error(task, settings_file, f"body '{body.name}' is listed twice", f'<JMPBody name="{body.name}">',
                         "each body once per task (flag scaling and marker moves in one <JMPBody>)", body.source.line)
        seen_bodies.add(body.name)
        if body.name not in model.bodies:
            close = close_matches(body.name, list(model.bodies))
            raise _error(task, settings_file, f"body '{body.name}' is not in the model {model.file}"
                         + (f"; close matches: {', '.join(close)}" if close else ""),
                         f'<JMPBody name="{body.name}">', "a body of the model")
    for element, names in (("<marker_names>", task.marker_names), ("<free_markers>", task.free_markers)):
        for name in names:
            for pool, where in ((model.marker_names, f"the model {model.file}"),
                                (marker_file_names, f"the marker file {task.marker_file_name}")):
                if name not in pool:
                    close = close_matches(name, list(pool))
                    raise _error(task, settings_file, f"marker '{name}' is not in {where}"
                                 + (f"; close matches: {', '.join(close)}" if close else ""),
                                 element, "markers present in both the model and the marker file")


def task_markers(model: Model, task: JmpTask, marker_file_names: Sequence[str]) -> tuple[str, ...]:
    """The markers a task uses (see module docstring), in model order."""
    if task.marker_names:
        return tuple(dict.fromkeys(task.marker_names))
    bodies: set[str] = set()
    for joint in task.joints:
        j = model.joint(joint.name)
        bodies.update((j.parent_body, j.child_body))
    for body in task.bodies:
        if body.scale_body or any(body.move_markers):
            bodies.add(body.name)
    in_file = set(marker_file_names)
    names = [m.name for m in model.markers if m.body in bodies and m.name in in_file]
    names += [n for n in task.free_markers if n not in names]
    return tuple(names)


def build_design(model: Model, task: JmpTask, marker_file_names: Sequence[str], *,
                 settings_file: str | None = None) -> TaskDesign:
    """The task's :class:`TaskDesign` for ``model`` (the model the task starts from)."""
    check_names(model, task, marker_file_names, settings_file)
    markers = task_markers(model, task, marker_file_names)
    if not markers:
        raise _error(task, settings_file, "no marker of the marker file is on the bodies the task changes",
                     "<marker_names>", "markers on the task's joints' bodies, or an explicit <marker_names>")
    bounded = _has_bounds(task)
    params = ModelParameters(model)
    params.scale_mass = False  # Model.scale(..., preserveMassDist=true): mass kept, inertia * s**2
    variables: list[DesignVariable] = []

    def frame_variables(joint_name: str, which: str, frame: JmpFrame) -> None:
        for kind, flags, bound in (("translation", frame.translation, frame.translation_bounds),
                                   ("orientation", frame.orientation, frame.orientation_bounds)):
            components = [i for i in range(3) if flags[i]]
            if not components:
                continue
            if bounded and not bound:
                warnings.warn(f"{settings_file}: {_task_label(task)}: joint '{joint_name}' {which} frame {kind} is "
                              f"flagged but has no <{kind}_bounds> while other frames have bounds: it is frozen "
                              "(bound 0), as in the original", stacklevel=3)
                continue
            width = bound if bounded else DEFAULT_BOUND
            path = params.joint_frame_path(joint_name, which)
            (params.frame_translation if kind == "translation" else params.frame_orientation)(path, components)
            file_values = getattr(model.frames[path], kind)
            for i in components:
                value = float(file_values[i])
                variables.append(DesignVariable(kind, path, i, f"{joint_name} {which} {kind} {_AXES[i]}", value,
                                                value - width, value + width, joint_name))

    for joint in task.joints:
        frame_variables(joint.name, "parent", joint.parent_frame_transformation)
        frame_variables(joint.name, "child", joint.child_frame_transformation)
    scaled = []
    for body in task.bodies:
        if body.scale_body:
            params.body_scale(body.name)
            scaled.append(body.name)
            lower = MIN_SCALE if bounded else max(MIN_SCALE, 1.0 - DEFAULT_BOUND)
            upper = np.inf if bounded else 1.0 + DEFAULT_BOUND
            variables.append(DesignVariable("scale", body.name, 0, f"{body.name} scale", 1.0, lower, upper))
    moving: dict[str, list[int]] = {}
    for body in task.bodies:
        axes = [i for i in range(3) if body.move_markers[i]]
        if not axes:
            continue
        for name in markers:
            if model.marker(name).body == body.name:
                moving.setdefault(name, [])
                moving[name] = sorted(set(moving[name]) | set(axes))
    for name in task.free_markers:
        moving[name] = [0, 1, 2]
    for name in markers:
        if name not in moving:
            continue
        params.marker_location(name, moving[name])
        for i in moving[name]:
            value = float(model.marker(name).location[i])
            width = np.inf if bounded else DEFAULT_BOUND
            variables.append(DesignVariable("marker", name, i, f"{name} location {_AXES[i]}", value,
                                            value - width, value + width))
    if not variables:
        raise _error(task, settings_file, "no parameter is flagged for optimization", "<JMPTask>",
                     "a true flag in a <JMPJoint>, <scale_body>true, <move_markers> or <free_markers>")
    unscaled = frozenset() if task.anatomical_markers else frozenset(scaled)
    return TaskDesign(parameters=params, variables=tuple(variables), marker_names=markers,
                      unscaled_marker_bodies=unscaled)

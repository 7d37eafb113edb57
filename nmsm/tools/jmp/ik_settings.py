"""OpenSim inverse-kinematics settings files, read as OpenSim's IK tool reads them.

Accepted: an IK setup (``<OpenSimDocument><InverseKinematicsTool>``), whose ``<IKTaskSet>``
may hold the tasks or name a task-set file (``<IKTaskSet file="tasks.xml"/>``, relative to
the setup's folder), and a bare task set (``<OpenSimDocument><IKTaskSet>``, as OpenSim's
examples ship marker weights), which gives only the tasks.

Read: the IKTaskSet (``IKMarkerTask`` name/apply/weight, ``IKCoordinateTask``
name/apply/weight/value_type/value), ``accuracy``, ``time_range``, ``marker_file``,
``coordinate_file``, ``model_file`` and ``output_motion_file``. Paths resolve as settings
paths do (:func:`nmsm.io.paths.resolve_path`: the file's folder, then its parent — the
tutorial's ``IKSettingsFiles/*.xml`` name ``MarkerFiles/...`` of the step folder). Empty
paths and ``Unassigned`` mean "not given".
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import attrs
from lxml import etree

from nmsm.errors import InputError
from nmsm.io.paths import resolve_path
from nmsm.io.xml_input import refuse_entities, xml_parser

_UNSET = {"", "unassigned"}


@attrs.frozen
class CoordinateTask:
    """Track a coordinate: ``weight * (q - value)**2`` (rad or m).

    ``value_type`` is ``default_value`` (the model's default), ``manual_value`` (``value``)
    or ``from_file`` (the settings' coordinate file).
    """

    name: str
    weight: float
    value_type: str = "default_value"
    value: float = 0.0


@attrs.frozen
class IkSettings:
    """What nmsm's inverse kinematics reads from an OpenSim IK settings file."""

    file: Path
    marker_weights: dict[str, float] | None
    coordinate_tasks: tuple[CoordinateTask, ...] = ()
    accuracy: float | None = None
    time_range: tuple[float, float] | None = None
    marker_file: Path | None = None
    coordinate_file: Path | None = None
    model_file: Path | None = None
    output_motion_file: Path | None = None
    constraint_weight: float = math.inf


def _text(elem: etree._Element, tag: str) -> str | None:
    child = elem.find(tag)
    if child is None or child.text is None:
        return None
    text = child.text.strip()
    return None if text.lower() in _UNSET else text


def _number(path: Path, elem: etree._Element, tag: str, text: str) -> float:
    try:
        return float(text.replace("Inf", "inf").replace("INF", "inf"))
    except ValueError:
        raise InputError(f"<{tag}> = '{text}' is not a number", file=path, line=elem.sourceline,
                         element=f"<{tag}>", expected="a number") from None


def _bool(path: Path, elem: etree._Element, text: str | None) -> bool:
    value = (text or "true").strip().lower()
    if value not in ("true", "false"):
        raise InputError(f"<apply> = '{text}'", file=path, line=elem.sourceline, element="<apply>",
                         expected="true or false")
    return value == "true"


def _parse(path: Path) -> etree._Element:
    try:
        root = etree.parse(str(path), xml_parser()).getroot()
    except OSError as exc:
        raise InputError(f"cannot read the IK settings file ({exc})", file=path) from None
    except etree.XMLSyntaxError as exc:
        raise InputError(f"malformed XML: {exc.msg}", file=path, line=exc.lineno, expected="well-formed XML") from None
    refuse_entities(root, path, "IK settings file")
    return root


def _find(root: etree._Element, tag: str) -> etree._Element | None:
    """``root`` itself, or its child, tagged ``tag``."""
    return root if root.tag == tag else root.find(tag)


def _task_set(path: Path, tool: etree._Element) -> tuple[Path, etree._Element | None]:
    """The file and element holding the tool's tasks: its ``<IKTaskSet>``, or the task set of
    the file that ``<IKTaskSet file="...">`` names."""
    task_set = tool.find("IKTaskSet")
    if task_set is None or not (task_set.get("file") or "").strip():
        return path, task_set
    reference = task_set.get("file", "").strip()
    source = resolve_path(reference, settings_file=path, line=task_set.sourceline, element='IKTaskSet file="..."',
                          kind="file")
    found = _find(_parse(source), "IKTaskSet")
    if found is None:
        raise InputError(f"no <IKTaskSet> in {source}", file=path, line=task_set.sourceline,
                         element='<IKTaskSet file="...">', expected="a file holding an OpenSim <IKTaskSet>")
    return source, found


def _tasks(path: Path, task_set: etree._Element | None) -> tuple[dict[str, float] | None, list[CoordinateTask]]:
    """Marker weights (``None`` without tasks) and coordinate tasks of an ``<IKTaskSet>``."""
    weights: dict[str, float] | None = None
    coordinate_tasks: list[CoordinateTask] = []
    if task_set is None:
        return weights, coordinate_tasks
    weights = {}
    for task in task_set.iter("IKMarkerTask", "IKCoordinateTask"):
        name = task.get("name")
        if not name:
            raise InputError(f"<{task.tag}> without a name", file=path, line=task.sourceline,
                             element=f"<{task.tag}>", expected='name="marker or coordinate"')
        if not _bool(path, task, _text(task, "apply")):
            continue
        weight_text = _text(task, "weight")
        weight = 1.0 if weight_text is None else _number(path, task, "weight", weight_text)
        if task.tag == "IKMarkerTask":
            weights[name] = weight
            continue
        value_type = (_text(task, "value_type") or "default_value").strip()
        if value_type not in ("default_value", "manual_value", "from_file"):
            raise InputError(f"<value_type> = '{value_type}'", file=path, line=task.sourceline,
                             element="<value_type>", expected="default_value, manual_value or from_file")
        value_text = _text(task, "value")
        value = 0.0 if value_text is None else _number(path, task, "value", value_text)
        coordinate_tasks.append(CoordinateTask(name, weight, value_type, value))
    if not weights and not coordinate_tasks:
        weights = None
    return weights, coordinate_tasks


def read_ik_settings(path: str | os.PathLike[str]) -> IkSettings:
    """Parse an OpenSim IK setup or task-set file (see module docstring)."""
    path = Path(path)
    root = _parse(path)
    tool = _find(root, "InverseKinematicsTool")
    if tool is None:
        task_set = _find(root, "IKTaskSet")
        if task_set is None:
            raise InputError(f"<{root.tag}> holds neither an <InverseKinematicsTool> nor an <IKTaskSet>", file=path,
                             line=root.sourceline,
                             expected="an OpenSim inverse-kinematics setup or IK task set "
                                      "(<OpenSimDocument><InverseKinematicsTool> or <OpenSimDocument><IKTaskSet>)")
        weights, coordinate_tasks = _tasks(path, task_set)
        return IkSettings(file=path, marker_weights=weights, coordinate_tasks=tuple(coordinate_tasks))
    weights, coordinate_tasks = _tasks(*_task_set(path, tool))
    accuracy_text = _text(tool, "accuracy")
    time_text = _text(tool, "time_range")
    time_range = None
    if time_text is not None:
        parts = time_text.split()
        if len(parts) != 2:
            raise InputError(f"<time_range> = '{time_text}'", file=path, element="<time_range>",
                             expected="two numbers: start and end time (s)")
        time_range = (_number(path, tool, "time_range", parts[0]), _number(path, tool, "time_range", parts[1]))
    constraint_text = _text(tool, "constraint_weight")

    def file_path(tag: str, must_exist: bool) -> Path | None:
        text = _text(tool, tag)
        if text is None:
            return None
        elem = tool.find(tag)
        return resolve_path(text, settings_file=path, line=elem.sourceline, element=tag,
                            must_exist=must_exist, kind="file" if must_exist else "any")

    return IkSettings(
        file=path,
        marker_weights=weights,
        coordinate_tasks=tuple(coordinate_tasks),
        accuracy=None if accuracy_text is None else _number(path, tool, "accuracy", accuracy_text),
        time_range=time_range,
        marker_file=file_path("marker_file", True),
        coordinate_file=file_path("coordinate_file", True),
        model_file=file_path("model_file", True),
        output_motion_file=file_path("output_motion_file", False),
        constraint_weight=math.inf if constraint_text is None else _number(path, tool, "constraint_weight",
                                                                            constraint_text),
    )

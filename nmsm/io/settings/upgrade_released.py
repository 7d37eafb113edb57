"""Elements of released 1.x NMSM Pipeline settings that the current schema replaced.

Files with root ``<NMSMPipelineDocument Version="1.x">`` are read by the current classes; this
step translates, in memory, what an earlier 1.x release wrote (``docs/settings-upgrade.md``,
"Released 1.x files"):

GCP ``<GCPContactSurface>``: ``<toe_joint>`` / ``<toes_joint>`` and ``<toe_coordinate>`` /
``<toes_coordinate>`` (1.0.x named the foot by its toe joint, 1.1.0 and later by
``<hindfoot_body>``; files of 1.1.0 may carry both). They are checked against the input model:
the joint must exist, the coordinate must belong to it, and the joint's parent body is the
hindfoot body; a ``<hindfoot_body>`` naming another body is an :class:`InputError` (the file
contradicts itself), a missing one is added. The old elements are then replaced by comments,
with one note per element name.

Elements that a 1.x release wrote and the current original no longer reads (:data:`UNUSED`)
are replaced by comments with one note per element name (not one "unknown element" warning
per occurrence).
"""

from __future__ import annotations

from lxml import etree

from nmsm.errors import InputError
from nmsm.io.settings.document import elements
from nmsm.io.settings.upgrader import Upgrader, child_of
from nmsm.io.settings.upgrade_legacy_personalization import _first_child, _last, _read_model

#: (tool element, parent element, element) -> the releases that wrote it; the current original
#: does not read it, so it has no effect
UNUSED: dict[tuple[str, str, str], str] = {
    ("MuscleTendonPersonalizationTool", "MTPSynergyExtrapolation", "task_prefixes"): "1.1",
}
_TOE_TAGS = ("toe_joint", "toes_joint", "toe_coordinate", "toes_coordinate")


def _unused(tool: etree._Element) -> list[etree._Element]:
    """Elements of ``tool`` listed in :data:`UNUSED`."""
    return [e for (tool_tag, parent, tag) in UNUSED if tool.tag == tool_tag
            for e in tool.iter(tag) if e.getparent() is not None and e.getparent().tag == parent]


def needed(root: etree._Element) -> bool:
    """Whether ``root`` holds an element that :func:`upgrade` translates."""
    tool = next(elements(root), None)
    if tool is None:
        return False
    toes = tool.tag == "GroundContactPersonalizationTool" and any(True for _ in tool.iter(*_TOE_TAGS))
    return toes or bool(_unused(tool))


def upgrade(up: Upgrader) -> None:
    """Translate the elements of earlier 1.x releases in ``up.root`` (see module docstring)."""
    tool = next(elements(up.root), None)
    if tool is None:
        return
    if tool.tag == "GroundContactPersonalizationTool":
        _gcp_toe_elements(up, tool)
    _drop_unused(up, tool)


def _drop_unused(up: Upgrader, tool: etree._Element) -> None:
    """Elements without effect replaced by comments, one note per element name."""
    version = up.root.get("Version", "?")
    found: dict[tuple[str, str], list[etree._Element]] = {}
    for element in _unused(tool):
        found.setdefault((str(element.getparent().tag), str(element.tag)), []).append(element)
    for (parent, tag), dropped in found.items():
        releases = UNUSED[(str(tool.tag), parent, tag)]
        for element in dropped:
            _replace(up, element, "no effect in NMSM Pipeline 1.5")
        lines = ", ".join(str(e.sourceline) for e in dropped)
        up.notes.append(f"<{tag}> in <{parent}> (line {lines}; written by NMSM Pipeline {releases}, this file says "
                        f'Version="{version}") has no effect in NMSM Pipeline 1.5 or nmsm: ignored')


def _joints(model: etree._Element) -> list[etree._Element]:
    return [j for j in model.iter() if isinstance(j.tag, str) and j.tag.endswith("Joint") and j.get("name")]


def _parent_body(joint: etree._Element) -> str | None:
    """The body a joint's parent frame is attached to (OpenSim 4 offset frame or OpenSim 3 ``<parent_body>``)."""
    parent_body = joint.findtext("parent_body")
    if parent_body:
        return _last(parent_body)
    frame_name = _last(joint.findtext("socket_parent_frame") or "")
    for frame in joint.iter("PhysicalOffsetFrame"):
        if frame.get("name") == frame_name:
            return _last(frame.findtext("socket_parent") or "") or None
    return frame_name or None


def _gcp_toe_elements(up: Upgrader, tool: etree._Element) -> None:
    surface_set = child_of(tool, "GCPContactSurfaceSet")
    if surface_set is None:
        return
    version = up.root.get("Version", "?")
    model: etree._Element | None = None
    model_read = False
    checked: dict[str, list[str]] = {}
    for surface in elements(surface_set):
        toe_joint = _first_child(surface, "toe_joint", "toes_joint")
        toe_coordinate = _first_child(surface, "toe_coordinate", "toes_coordinate")
        old = [e for e in (toe_joint, toe_coordinate) if e is not None]
        if not old:
            continue
        if not model_read:
            model, model_read = _read_model(up, tool), True
        hindfoot = child_of(surface, "hindfoot_body")
        if model is None:
            if hindfoot is None:
                continue  # the reader then asks for <hindfoot_body>
            for element in old:
                up.drop(element, "not checked: the model could not be read; <hindfoot_body> is used")
            continue
        body = _toe_parent_body(up, model, toe_joint, toe_coordinate)
        stated = (hindfoot.text or "").strip() if hindfoot is not None else ""
        anchor = old[0]
        if stated and stated != body:
            raise InputError(
                f"<hindfoot_body>{stated}</hindfoot_body> contradicts <{anchor.tag}>{(anchor.text or '').strip()}"
                f"</{anchor.tag}>, whose parent body in the model is '{body}'",
                file=up.path, line=hindfoot.sourceline, element="<hindfoot_body>",
                expected=f"'{body}' (or remove <{anchor.tag}>: the current schema reads <hindfoot_body> only)",
            )
        if hindfoot is None:
            surface.insert(surface.index(anchor), up.new("hindfoot_body", body, like=anchor))
        elif not stated:
            hindfoot.text = body
        for element in old:
            checked.setdefault(str(element.tag), []).append(f"{(element.text or '').strip()} -> {body}")
            _replace(up, element, "read as <hindfoot_body> (the toe joint's parent body)")
    for tag, found in checked.items():
        up.notes.append(
            f"<{tag}> (written by NMSM Pipeline 1.0; this file says Version=\"{version}\") checked against the model "
            f"and read as <hindfoot_body>, the toe joint's parent body: {', '.join(found)}"
        )


def _replace(up: Upgrader, element: etree._Element, why: str) -> None:
    """``element`` replaced by a comment quoting it (saying ``why``), without a note of its own."""
    notes = len(up.notes)
    up.drop(element, why)
    del up.notes[notes:]


def _toe_parent_body(up: Upgrader, model: etree._Element, toe_joint: etree._Element | None,
                     toe_coordinate: etree._Element | None) -> str:
    """The parent body of the toe joint named by ``toe_joint`` and/or ``toe_coordinate``, both
    checked against the model."""
    joints = _joints(model)
    joint = None
    if toe_joint is not None:
        name = (toe_joint.text or "").strip()
        joint = next((j for j in joints if j.get("name") == name), None)
        if joint is None:
            raise InputError(f"'{name}' is not a joint of the input model", file=up.path, line=toe_joint.sourceline,
                             element=f"<{toe_joint.tag}>", expected="the name of the foot's toe joint")
    if toe_coordinate is not None:
        name = (toe_coordinate.text or "").strip()
        owner = next((j for j in joints if any(c.get("name") == name for c in j.iter("Coordinate"))), None)
        if owner is None:
            raise InputError(f"'{name}' is not a coordinate of the input model", file=up.path,
                             line=toe_coordinate.sourceline, element=f"<{toe_coordinate.tag}>",
                             expected="the coordinate of the foot's toe joint")
        if joint is not None and owner is not joint:
            raise InputError(
                f"<{toe_coordinate.tag}>{name}</{toe_coordinate.tag}> belongs to joint '{owner.get('name')}', "
                f"not to <{toe_joint.tag}>{joint.get('name')}</{toe_joint.tag}>",  # type: ignore[union-attr]
                file=up.path, line=toe_coordinate.sourceline, element=f"<{toe_coordinate.tag}>",
                expected="the coordinate of the toe joint named in the same <GCPContactSurface>",
            )
        joint = owner
    assert joint is not None
    body = _parent_body(joint)
    if not body:
        anchor = toe_joint if toe_joint is not None else toe_coordinate
        raise InputError(f"the parent body of joint '{joint.get('name')}' is not found in the input model",
                         file=up.path, line=anchor.sourceline if anchor is not None else None,
                         element="<hindfoot_body>", expected="<hindfoot_body> naming the hindfoot body")
    return body

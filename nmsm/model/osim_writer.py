"""Writing model changes back into an ``.osim`` file, touching nothing else.

:class:`OsimWriter` reads a model file, records changes to property values (joint frame
translation/orientation, marker locations, muscle parameters, body mass properties, the
effects of a uniform body scale), and writes the file with exactly those values replaced
in the original text: comments, formatting and every other element stay byte-for-byte
as they were. A property missing from the file is added next to its siblings. Numbers
are written with the shortest text that reads back to the same double.

Old-format files (< 40000) are written from their OpenSim-upgraded copy (see
:mod:`nmsm.model.osim`).

Example::

    writer = OsimWriter("model.osim")
    writer.set_joint_frame("knee_r", "parent", orientation=[-0.07, 0.0, 0.12])
    writer.set_marker_location("R_Knee", [0.0, -0.4, 0.05])
    writer.write("model_personalized.osim")
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

from nmsm.errors import ModelError
from nmsm.model.functions import find_function
from nmsm.model.osim import CURRENT_FORMAT, file_version, python_codec, read_xml, upgraded_copy
from nmsm.model.parse_forces import MUSCLE_TAGS
from nmsm.model.xml_tree import XmlReader, component_path, in_defaults, resolve_path

#: muscle properties :meth:`OsimWriter.set_muscle_property` may change
MUSCLE_PROPERTIES = ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length",
                     "pennation_angle_at_optimal", "max_contraction_velocity", "appliesForce")


def format_number(value: float) -> str:
    """Shortest decimal text that reads back to the same double."""
    value = float(value)
    if value == 0.0:
        return "0"
    if np.isinf(value):
        return "Inf" if value > 0 else "-Inf"
    return repr(value)


def format_vector(values: Sequence[float]) -> str:
    return " ".join(format_number(v) for v in values)


class OsimWriter:
    """Records property changes of one ``.osim`` file and writes them (see module docstring)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        tree = read_xml(self.path)
        self.source = self.path
        version = file_version(tree, self.path)
        if version and version < CURRENT_FORMAT:
            self.source = upgraded_copy(self.path)
            tree = read_xml(self.source)
        self.tree = tree
        #: the file's declared encoding (UTF-8, or e.g. ISO-8859-1, which OpenSim reads too), kept on writing
        self.encoding = python_codec(tree)
        self.text = self.source.read_text(encoding=self.encoding)
        self.reader = XmlReader(tree.getroot(), self.path)
        # lines as the XML parser numbers them: ends at "\n" only (str.splitlines also ends lines
        # at U+0085, U+2028, U+2029, which are text in XML: an edit would land lines too early)
        lines = self.text.split("\n")
        lengths = [len(line) + 1 for line in lines[:-1]] + [len(lines[-1])]
        self._line_offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(int)
        self._edits: dict[Any, tuple[etree._Element, str, str]] = {}  # key -> (parent, tag, new text)
        self._frames = {component_path(e): e for e in self.reader.elements(["Ground", "Body", "PhysicalOffsetFrame"])}

    # ------------------------------------------------------------------ lookups
    def _named(self, tags: Sequence[str], name: str, what: str) -> etree._Element:
        for elem in self.reader.elements(tags):
            if elem.get("name") == name:
                return elem
        raise ModelError(f"no {what} '{name}'", file=self.path, expected=f"a {what} of the model")

    def _frame(self, frame_path: str) -> etree._Element:
        elem = self._frames.get(frame_path)
        if elem is None:
            raise ModelError(f"no frame '{frame_path}'", file=self.path, expected="a frame path of the model")
        return elem

    def current(self, elem: etree._Element, tag: str, default: Sequence[float] | None = None) -> np.ndarray:
        """Current value (after recorded edits) of a numeric property."""
        edit = self._edits.get((id(elem), tag))
        if edit is not None:
            return np.array([float(v) for v in edit[2].split()])
        return self.reader.floats(elem, tag, default)

    def _set(self, elem: etree._Element, tag: str, text: str) -> None:
        self._edits[(id(elem), tag)] = (elem, tag, text)

    # ------------------------------------------------------------------ changes
    def set_frame_translation(self, frame_path: str, translation: Sequence[float]) -> None:
        """Translation (m) of a PhysicalOffsetFrame in its parent frame."""
        elem = self._frame(frame_path)
        if elem.tag != "PhysicalOffsetFrame":
            raise ModelError(f"frame '{frame_path}' is a {elem.tag}", file=self.path, expected="a PhysicalOffsetFrame")
        self._set(elem, "translation", format_vector(_vector3(translation, "translation")))

    def set_frame_orientation(self, frame_path: str, orientation: Sequence[float]) -> None:
        """Body-fixed X-Y-Z orientation (rad) of a PhysicalOffsetFrame in its parent frame."""
        elem = self._frame(frame_path)
        if elem.tag != "PhysicalOffsetFrame":
            raise ModelError(f"frame '{frame_path}' is a {elem.tag}", file=self.path, expected="a PhysicalOffsetFrame")
        self._set(elem, "orientation", format_vector(_vector3(orientation, "orientation")))

    def joint_frame_path(self, joint: str, which: str) -> str:
        from nmsm.model.components import JOINT_TYPES

        elem = self._named(JOINT_TYPES, joint, "joint")
        tag = {"parent": "socket_parent_frame", "child": "socket_child_frame"}.get(which)
        if tag is None:
            raise ValueError(f"which must be 'parent' or 'child', not '{which}'")
        reference = self.reader.text(elem, tag) or ""
        path = resolve_path(reference, component_path(elem))
        if path not in self._frames:
            name = reference.rstrip("/").split("/")[-1]
            matches = [p for p in self._frames if p.rsplit("/", 1)[-1] == name]
            if len(matches) != 1:
                raise ModelError(f"joint '{joint}' {which} frame '{reference}' not found", file=self.path)
            path = matches[0]
        return path

    def set_joint_frame(self, joint: str, which: str, *, translation: Sequence[float] | None = None,
                        orientation: Sequence[float] | None = None) -> None:
        """Translation (m) and/or orientation (rad) of a joint's parent or child offset frame."""
        path = self.joint_frame_path(joint, which)
        if translation is not None:
            self.set_frame_translation(path, translation)
        if orientation is not None:
            self.set_frame_orientation(path, orientation)

    def set_marker_location(self, marker: str, location: Sequence[float]) -> None:
        """Location (m) of a marker in its frame."""
        elem = self._named(["Marker"], marker, "marker")
        self._set(elem, "location", format_vector(_vector3(location, "location")))

    def set_muscle_property(self, muscle: str, name: str, value: float | bool) -> None:
        """One of :data:`MUSCLE_PROPERTIES` of a muscle (N, m, rad, optimal lengths per s)."""
        if name not in MUSCLE_PROPERTIES:
            raise ValueError(f"muscle property must be one of {', '.join(MUSCLE_PROPERTIES)}, not '{name}'")
        elem = self._named(MUSCLE_TAGS, muscle, "muscle")
        text = ("true" if value else "false") if name == "appliesForce" else format_number(float(value))
        self._set(elem, name, text)

    def set_body_mass_properties(self, body: str, *, mass: float | None = None,
                                 mass_center: Sequence[float] | None = None,
                                 inertia: np.ndarray | None = None) -> None:
        """Mass (kg), centre of mass (m) and inertia about it (3x3 or Ixx Iyy Izz Ixy Ixz Iyz)."""
        elem = self._named(["Body"], body, "body")
        if mass is not None:
            self._set(elem, "mass", format_number(mass))
        if mass_center is not None:
            self._set(elem, "mass_center", format_vector(_vector3(mass_center, "mass_center")))
        if inertia is not None:
            i = np.asarray(inertia, dtype=float)
            six = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]] if i.shape == (3, 3) else list(i.reshape(6))
            self._set(elem, "inertia", format_vector(six))

    def scale_body(self, body: str, factor: float, *, scale_mass: bool = False) -> None:
        """Apply a uniform scale ``factor`` to ``body`` as nmsm's kinematics do (see
        :mod:`nmsm.model.parameters`): offset frames attached to it, markers, path points,
        wrap objects and contact geometry on it, translation functions of CustomJoints whose
        parent frame is on it, its centre of mass and inertia (and mass with ``scale_mass``),
        the ``scale_factors`` of its attached geometry (display meshes, as ``Model.scale``).
        Muscle optimal fibre and tendon slack lengths are not changed (set them with
        :meth:`set_muscle_property`)."""
        from nmsm.model.osim import load_model

        factor = float(factor)
        model = load_model(self.path)
        if body not in model.bodies:
            raise ModelError(f"no body '{body}'", file=self.path, expected="a body of the model")
        on_body = {p for p, f in model.frames.items() if f.base_body == body}
        for path, frame in model.frames.items():
            if frame.kind == "offset" and frame.parent in on_body:
                elem = self._frames[path]
                self._set(elem, "translation", format_vector(self.current(elem, "translation", [0, 0, 0]) * factor))
        for elem in self.reader.elements(["Marker", "PathPoint", "ConditionalPathPoint", "MovingPathPoint"]):
            frame = _socket_frame(self, elem, "socket_parent_frame")
            if frame in on_body:
                self._set(elem, "location", format_vector(self.current(elem, "location", [0, 0, 0]) * factor))
                if elem.tag == "MovingPathPoint":
                    for axis in "xyz":
                        self._scale_function(find_function(elem.find(f"{axis}_location")), factor)
        for elem in self.reader.elements(["ContactSphere", "ContactHalfSpace"]):
            if _socket_frame(self, elem, "socket_frame") in on_body:
                self._set(elem, "location", format_vector(self.current(elem, "location", [0, 0, 0]) * factor))
                if elem.tag == "ContactSphere":
                    self._set(elem, "radius", format_number(self.current(elem, "radius", [0.0])[0] * factor))
        for elem in self.reader.elements(["WrapCylinder", "WrapEllipsoid", "WrapSphere", "WrapTorus"]):
            owner = next((a for a in elem.iterancestors() if a.tag in ("Ground", "Body", "PhysicalOffsetFrame")), None)
            if owner is None or component_path(owner) not in on_body:
                continue
            self._set(elem, "translation", format_vector(self.current(elem, "translation", [0, 0, 0]) * factor))
            for tag in ("radius", "length", "inner_radius", "outer_radius"):
                if elem.find(tag) is not None:
                    self._set(elem, tag, format_number(self.current(elem, tag)[0] * factor))
            if elem.find("dimensions") is not None:
                self._set(elem, "dimensions", format_vector(self.current(elem, "dimensions") * factor))
        for joint in model.joints:
            if joint.type != "CustomJoint" or joint.parent_body != body:
                continue
            jelem = self._named(["CustomJoint"], joint.name, "joint")
            for axis_elem in jelem.find("SpatialTransform").findall("TransformAxis"):
                if not axis_elem.get("name", "").startswith("translation"):
                    continue
                func = find_function(axis_elem)
                if func is None:
                    if not self.reader.names(axis_elem, "coordinates"):
                        continue  # constant 0
                    continue  # default LinearFunction(1, 0): a coordinate axis, not scaled
                if func.tag == "LinearFunction":
                    coefs = self.current(func, "coefficients", [1, 0])
                    if coefs[0] == 1.0 and coefs[1] == 0.0:
                        continue
                self._scale_function(func, factor)
        elem = self._named(["Body"], body, "body")
        mass = self.current(elem, "mass", [0.0])[0]
        inertia = self.current(elem, "inertia", [0, 0, 0, 0, 0, 0])
        self._set(elem, "mass_center", format_vector(self.current(elem, "mass_center", [0, 0, 0]) * factor))
        if scale_mass:
            self._set(elem, "mass", format_number(mass * factor**3))
            self._set(elem, "inertia", format_vector(inertia * factor**5))
        else:
            self._set(elem, "inertia", format_vector(inertia * factor**2))
        attached = elem.find("attached_geometry")
        for geometry in attached if attached is not None else ():
            if isinstance(geometry.tag, str) and geometry.find("scale_factors") is not None:
                self._set(geometry, "scale_factors", format_vector(self.current(geometry, "scale_factors") * factor))

    def _scale_function(self, func: etree._Element | None, factor: float) -> None:
        """Multiply a function's values by ``factor`` (exact for every supported type)."""
        if func is None:
            return
        tag = func.tag
        if tag == "Constant":
            self._set(func, "value", format_number(self.current(func, "value", [0.0])[0] * factor))
        elif tag in ("LinearFunction", "PolynomialFunction"):
            self._set(func, "coefficients", format_vector(self.current(func, "coefficients") * factor))
        elif tag in ("SimmSpline", "NaturalCubicSpline", "PiecewiseLinearFunction"):
            self._set(func, "y", format_vector(self.current(func, "y") * factor))
        elif tag == "MultiplierFunction":
            self._set(func, "scale", format_number(self.current(func, "scale", [1.0])[0] * factor))
        else:
            raise ModelError(f"cannot scale a {tag}", file=self.path, line=func.sourceline,
                             expected="Constant, LinearFunction, PolynomialFunction, a spline or MultiplierFunction")

    def apply_parameters(self, parameters: Any, values: Sequence[float]) -> None:
        """Write numeric values of :class:`~nmsm.model.parameters.ModelParameters` symbols:
        frame translations/orientations and marker locations first, then body scales."""
        import casadi as cs

        values = np.asarray(values, dtype=float).reshape(-1)
        if values.size != parameters.size:
            raise ValueError(f"expected {parameters.size} parameter values, got {values.size}")
        evaluate = cs.Function("params", [parameters.symbols], [
            cs.vertcat(*parameters.translations.values(), *parameters.orientations.values(),
                       *parameters.marker_locations.values(), *parameters.scales.values())
            if parameters.size else cs.SX(0, 1)])
        flat = np.array(evaluate(values)).reshape(-1)
        k = 0
        for path in parameters.translations:
            self.set_frame_translation(path, flat[k:k + 3])
            k += 3
        for path in parameters.orientations:
            self.set_frame_orientation(path, flat[k:k + 3])
            k += 3
        for marker in parameters.marker_locations:
            self.set_marker_location(marker, flat[k:k + 3])
            k += 3
        for body in parameters.scales:
            self.scale_body(body, flat[k], scale_mass=parameters.scale_mass)
            k += 1

    # ------------------------------------------------------------------ output
    @property
    def n_changes(self) -> int:
        return len(self._edits)

    def render(self) -> str:
        """The file's text with the recorded changes."""
        patches: list[tuple[int, int, str]] = []
        for parent, tag, value in self._edits.values():
            child = parent.find(tag)
            if child is not None:
                patches.append(self._replace_patch(child, value))
            else:
                patches.append(self._insert_patch(parent, tag, value))
        patches.sort(key=lambda p: p[0])
        out = []
        position = 0
        for start, end, text in patches:
            if start < position:
                raise ModelError("overlapping edits", file=self.path)
            out.append(self.text[position:start])
            out.append(text)
            position = end
        out.append(self.text[position:])
        return "".join(out)

    def write(self, path: str | Path | None = None) -> Path:
        """Write the changed model (to ``path``, default: over the file read)."""
        target = Path(path) if path is not None else self.path
        target.write_text(self.render(), encoding=self.encoding, errors="xmlcharrefreplace")
        return target

    def _start_tag(self, elem: etree._Element) -> tuple[int, int, bool]:
        """(offset of '<tag', offset after the start tag's '>', self-closing?) in the text."""
        line = elem.sourceline
        if line is None:
            raise ModelError(f"cannot locate <{elem.tag}> in the file text", file=self.path)
        offset = int(self._line_offsets[line - 1])
        match = re.compile(rf"<{re.escape(elem.tag)}(\s[^>]*)?(/?)>").search(self.text, offset)
        if match is None:
            raise ModelError(f"cannot locate <{elem.tag}> at line {line}", file=self.path)
        return match.start(), match.end(), match.group(2) == "/"

    def _replace_patch(self, child: etree._Element, value: str) -> tuple[int, int, str]:
        start, after, closed = self._start_tag(child)
        if closed:
            return start, after, f"<{child.tag}>{value}</{child.tag}>"
        end = self.text.find(f"</{child.tag}>", after)
        if end < 0:
            raise ModelError(f"no closing tag for <{child.tag}> at line {child.sourceline}", file=self.path)
        return after, end, value

    def _insert_patch(self, parent: etree._Element, tag: str, value: str) -> tuple[int, int, str]:
        start, after, closed = self._start_tag(parent)
        if closed:
            raise ModelError(f"<{parent.tag}> at line {parent.sourceline} is empty", file=self.path)
        line_start = self.text.rfind("\n", 0, start) + 1
        indent = re.match(r"[ \t]*", self.text[line_start:start]).group(0)
        child_indent = indent + ("\t" if "\t" in indent or not indent else "    ")
        return after, after, f"\n{child_indent}<{tag}>{value}</{tag}>"


def _vector3(values: Sequence[float], what: str) -> np.ndarray:
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size != 3 or not np.all(np.isfinite(v)):
        raise ValueError(f"{what} must be 3 finite numbers, got {values!r}")
    return v


def _socket_frame(writer: OsimWriter, elem: etree._Element, tag: str) -> str | None:
    reference = writer.reader.text(elem, tag)
    if reference is None or in_defaults(elem):
        return None
    path = resolve_path(reference, component_path(elem))
    if path in writer._frames:
        return path
    name = reference.rstrip("/").split("/")[-1]
    matches = [p for p in writer._frames if p.rsplit("/", 1)[-1] == name]
    return matches[0] if len(matches) == 1 else None

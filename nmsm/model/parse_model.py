"""Building a :class:`~nmsm.model.components.Model` from a current-format (4.x) ``.osim``
XML tree: frames, bodies, joints and coordinates (tree order), coordinate couplers,
markers, wrap objects, then the forces (:mod:`nmsm.model.parse_forces`).

Anything nmsm cannot represent raises :class:`~nmsm.errors.ModelError` naming the
component and the file.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from lxml import etree

from nmsm.errors import ModelError
from nmsm.model.components import (
    GROUND,
    JOINT_TYPES,
    Body,
    Coordinate,
    CoordinateCoupler,
    Frame,
    Joint,
    Marker,
    Model,
    TransformAxis,
    WrapObject,
)
from nmsm.model.functions import Constant, LinearFunction, find_function, parse_function
from nmsm.model.parse_forces import (
    ACTUATOR_TAGS,
    CONTACT_GEOMETRY_TAGS,
    MUSCLE_TAGS,
    OTHER_FORCE_TAGS,
    other_force,
    parse_actuator,
    parse_contact_geometry,
    parse_groups,
    parse_muscle,
    parse_smooth_contact,
)
from nmsm.model.rotations import body_xyz
from nmsm.model.xml_tree import XmlReader, component_path, resolve_path

OTHER_JOINT_TAGS = frozenset({"EllipsoidJoint", "ScapulothoracicJoint", "ConstantCurvatureJoint", "CMC_Joint_Deprecated"})
FRAME_TAGS = frozenset({"Ground", "Body", "PhysicalOffsetFrame"})
OTHER_FRAME_TAGS = frozenset({"StationDefinedFrame", "OffsetFrame"})
WRAP_TAGS = frozenset({"WrapCylinder", "WrapEllipsoid", "WrapSphere", "WrapTorus", "WrapCylinderObst",
                       "WrapSphereObst", "WrapDoubleCylinderObst"})
CONSTRAINT_TAGS_IGNORED = frozenset(
    {"WeldConstraint", "PointConstraint", "PointOnLineConstraint", "ConstantDistanceConstraint",
     "RollingOnSurfaceConstraint", "CoordinateCouplerConstraint"}
)

#: OpenSim's default coordinate range (rad or m) when <range> is absent
DEFAULT_COORDINATE_RANGE = (-10.0, 10.0)

#: (number of coordinates, motion types) of the fixed joint types
_JOINT_LAYOUT: dict[str, tuple[str, ...]] = {
    "PinJoint": ("rotational",),
    "SliderJoint": ("translational",),
    "WeldJoint": (),
    "UniversalJoint": ("rotational", "rotational"),
    "PlanarJoint": ("rotational", "translational", "translational"),
    "GimbalJoint": ("rotational",) * 3,
    "BallJoint": ("rotational",) * 3,
    "FreeJoint": ("rotational",) * 3 + ("translational",) * 3,
}


class _Parser:
    def __init__(self, root: etree._Element, file: str) -> None:
        self.reader = XmlReader(root, file)
        self.file = file
        self.frame_elems: dict[str, etree._Element] = {}
        self.frames: dict[str, Frame] = {}
        self.coordinate_paths: dict[str, str] = {}  # path -> coordinate name

    # ------------------------------------------------------------------ frames
    def parse_frames(self) -> None:
        r = self.reader
        for elem in r.elements(OTHER_FRAME_TAGS):
            raise r.error(elem, f"frame type '{elem.tag}' is not supported", expected="Body or PhysicalOffsetFrame")
        for elem in r.elements(FRAME_TAGS):
            path = component_path(elem)
            if path in self.frame_elems:
                raise r.error(elem, f"two frames have the path '{path}'", expected="unique component names")
            self.frame_elems[path] = elem
        if not any(e.tag == "Ground" for e in self.frame_elems.values()):
            self.frames["/ground"] = Frame(GROUND, "/ground", "ground", base_body=GROUND)
        for path, elem in self.frame_elems.items():
            name = elem.get("name", "")
            if elem.tag == "Ground":
                self.frames[path] = Frame(name or GROUND, path, "ground", base_body=GROUND, xml_line=elem.sourceline)
            elif elem.tag == "Body":
                self.frames[path] = Frame(name, path, "body", base_body=name, xml_line=elem.sourceline)
        for path, elem in self.frame_elems.items():
            if elem.tag != "PhysicalOffsetFrame":
                continue
            parent = self._resolve_frame_path(elem, "socket_parent", path)
            self.frames[path] = Frame(
                elem.get("name", ""), path, "offset", parent=parent,
                translation=self.reader.floats(elem, "translation", [0, 0, 0], size=3),
                orientation=self.reader.floats(elem, "orientation", [0, 0, 0], size=3),
                xml_line=elem.sourceline,
            )
        for frame in self.frames.values():
            self._place(frame, set())

    def _place(self, frame: Frame, visiting: set[str]) -> None:
        if frame.base_body:
            return
        if frame.path in visiting:
            raise ModelError("offset frames form a cycle", file=self.file, element=f"PhysicalOffsetFrame '{frame.name}'")
        visiting.add(frame.path)
        parent = self.frames[frame.parent]
        self._place(parent, visiting)
        rotation = body_xyz(frame.orientation)
        frame.base_body = parent.base_body
        frame.rotation_in_base = parent.rotation_in_base @ rotation
        frame.origin_in_base = parent.origin_in_base + parent.rotation_in_base @ frame.translation

    def _resolve_frame_path(self, elem: etree._Element, tag: str, owner_path: str) -> str:
        reference = self.reader.text(elem, tag)
        if reference is None:
            raise self.reader.error(elem, f"missing <{tag}>", expected="the path of a frame")
        path = resolve_path(reference, owner_path)
        if path in self.frame_elems or path in self.frames:
            return path
        name = reference.rstrip("/").split("/")[-1]
        if name == "ground" and "/ground" in self.frame_elems:
            return "/ground"
        candidates = [p for p in self.frame_elems if p.rsplit("/", 1)[-1] == name]
        if len(candidates) == 1:
            return candidates[0]
        raise self.reader.error(
            elem, f"<{tag}> '{reference}' names no frame" + (" uniquely" if candidates else ""),
            expected="the path of a Body, Ground or PhysicalOffsetFrame",
        )

    def frame_of(self, elem: etree._Element, tag: str, owner_path: str) -> tuple[str, str]:
        path = self._resolve_frame_path(elem, tag, owner_path)
        return path, self.frames[path].base_body

    def body_of(self, elem: etree._Element, tag: str) -> str:
        """A body named by a plain name or path property (actuators)."""
        reference = self.reader.text(elem, tag) or self.reader.text(elem, f"socket_{tag}")
        if not reference:
            raise self.reader.error(elem, f"missing <{tag}>", expected="a body name")
        name = reference.rstrip("/").split("/")[-1]
        if name == GROUND:
            return GROUND
        for frame in self.frames.values():
            if frame.kind == "body" and frame.name == name:
                return name
        raise self.reader.error(elem, f"<{tag}> '{reference}' names no body", expected="a body of the model")

    # ------------------------------------------------------------------ bodies
    def parse_bodies(self) -> dict[str, Body]:
        bodies: dict[str, Body] = {}
        r = self.reader
        for path, elem in self.frame_elems.items():
            if elem.tag != "Body":
                continue
            name = elem.get("name", "")
            if name in bodies:
                raise r.error(elem, f"two bodies are named '{name}'", expected="unique body names")
            i6 = r.floats(elem, "inertia", [0, 0, 0, 0, 0, 0], size=6)
            inertia = np.array([[i6[0], i6[3], i6[4]], [i6[3], i6[1], i6[5]], [i6[4], i6[5], i6[2]]])
            mass, center = r.float(elem, "mass", 0.0), r.floats(elem, "mass_center", [0, 0, 0], size=3)
            for tag, values in (("mass", [mass]), ("mass_center", center), ("inertia", i6)):
                if not np.all(np.isfinite(values)):
                    raise r.error(elem, f"body '{name}': <{tag}> is not finite", expected="finite numbers")
            if mass < 0:  # OpenSim refuses it too ("unspecified or negative mass")
                raise r.error(elem, f"body '{name}' has negative mass {mass:g} kg", expected="a mass >= 0 kg")
            bodies[name] = Body(name, path, mass, center, inertia)
        return bodies

    # ------------------------------------------------------------------ joints
    def parse_joints(self) -> tuple[list[Joint], list[Coordinate]]:
        r = self.reader
        for elem in r.elements(OTHER_JOINT_TAGS):
            raise r.error(elem, f"joint type '{elem.tag}' is not supported",
                          expected="one of " + ", ".join(JOINT_TYPES))
        joints: list[Joint] = []
        coordinates: list[Coordinate] = []
        for elem in r.elements(JOINT_TYPES):
            joint, coords = self._parse_joint(elem)
            joints.append(joint)
            coordinates.extend(coords)
        names = [c.name for c in coordinates]
        duplicates = sorted({n for n in names if names.count(n) > 1})
        if duplicates:
            raise ModelError(f"coordinate names used twice: {', '.join(duplicates)}", file=self.file,
                             element="JointSet", expected="unique coordinate names")
        return joints, coordinates

    def _coordinate(self, elem: etree._Element | None, name: str, joint: str, motion: str) -> Coordinate:
        r = self.reader
        if elem is None:
            return Coordinate(name, joint, motion, DEFAULT_COORDINATE_RANGE)
        rng = r.floats(elem, "range", DEFAULT_COORDINATE_RANGE, size=2)
        if np.isnan(rng).any() or rng[0] > rng[1]:
            raise r.error(elem, f"coordinate '{name}': <range> {rng[0]:g} {rng[1]:g} is not a range",
                          expected="<range>MIN MAX</range> with MIN <= MAX (rad, or m for translations)")
        return Coordinate(
            name, joint, motion, (float(rng[0]), float(rng[1])),
            default_value=r.float(elem, "default_value", 0.0),
            default_speed=r.float(elem, "default_speed_value", 0.0),
            locked=r.bool(elem, "locked", False),
            clamped=r.bool(elem, "clamped", False),
            prescribed=r.bool(elem, "prescribed", False),
        )

    def _parse_joint(self, elem: etree._Element) -> tuple[Joint, list[Coordinate]]:
        r = self.reader
        name = elem.get("name", "")
        path = component_path(elem)
        if r.bool(elem, "reverse", False):
            raise r.error(elem, "reversed joints are not supported", expected="<reverse>false</reverse>")
        parent, parent_body = self.frame_of(elem, "socket_parent_frame", path)
        child, child_body = self.frame_of(elem, "socket_child_frame", path)
        if child_body == GROUND:
            raise r.error(elem, "the child frame is fixed to ground", expected="a child frame on a body")
        holder = elem.find("coordinates")
        xml_coords = [c for c in (holder if holder is not None else []) if isinstance(c.tag, str) and c.tag == "Coordinate"]
        by_name = {c.get("name", ""): c for c in xml_coords}
        axes: tuple[TransformAxis, ...] = ()
        if elem.tag == "CustomJoint":
            axes = self._transform_axes(elem, name)
            order: list[str] = []
            for axis in axes:
                for cname in axis.coordinates:
                    if cname not in order:
                        order.append(cname)
            unused = [c for c in by_name if c not in order]
            if unused:
                raise r.error(elem, f"coordinates {', '.join(unused)} drive no transform axis",
                              expected="every coordinate used by the SpatialTransform")
            motions = [_custom_motion_type(cname, axes) for cname in order]
        else:
            motions = list(_JOINT_LAYOUT[elem.tag])
            if len(xml_coords) > len(motions):
                raise r.error(elem, f"has {len(xml_coords)} coordinates", expected=f"{len(motions)} for a {elem.tag}")
            order = [c.get("name", "") for c in xml_coords]
            order += [f"{name}_coord_{i}" for i in range(len(order), len(motions))]
        for cname in order:
            self.coordinate_paths[f"{path}/{cname}"] = cname
        coords = [self._coordinate(by_name.get(cname), cname, name, motion) for cname, motion in zip(order, motions)]
        joint = Joint(name, elem.tag, path, parent, child, parent_body, child_body, tuple(order), axes,
                      xml_line=elem.sourceline)
        return joint, coords

    def _transform_axes(self, joint_elem: etree._Element, joint_name: str) -> tuple[TransformAxis, ...]:
        r = self.reader
        st = joint_elem.find("SpatialTransform")
        if st is None:
            raise r.error(joint_elem, "CustomJoint without <SpatialTransform>", expected="a SpatialTransform")
        defaults = {"rotation1": (1, 0, 0), "rotation2": (0, 1, 0), "rotation3": (0, 0, 1),
                    "translation1": (1, 0, 0), "translation2": (0, 1, 0), "translation3": (0, 0, 1)}
        found = {ta.get("name"): ta for ta in st.findall("TransformAxis")}
        axes = []
        for axis_name, default_axis in defaults.items():
            ta = found.get(axis_name)
            if ta is None:
                axes.append(TransformAxis(axis_name, (), default_axis, Constant(0.0)))
                continue
            coords = r.names(ta, "coordinates")
            direction = r.floats(ta, "axis", default_axis, size=3)
            if np.linalg.norm(direction) == 0.0:
                raise r.error(ta, f"joint '{joint_name}' {axis_name} has a zero axis", expected="a nonzero axis")
            func_elem = find_function(ta)
            if len(coords) > 1:
                raise r.error(ta, f"joint '{joint_name}' {axis_name} depends on {len(coords)} coordinates",
                              expected="at most one coordinate per transform axis")
            if func_elem is None:
                function = LinearFunction(1.0, 0.0) if coords else Constant(0.0)
            else:
                function = parse_function(func_elem, file=self.file, owner=f"CustomJoint '{joint_name}' {axis_name}")
            axes.append(TransformAxis(axis_name, coords, direction, function))
        return tuple(axes)

    def coordinate_of(self, elem: etree._Element, tag: str) -> str:
        """A coordinate named by a socket path or a plain name."""
        reference = self.reader.text(elem, tag)
        if not reference:
            raise self.reader.error(elem, f"missing <{tag}>", expected="a coordinate")
        path = resolve_path(reference, component_path(elem))
        if path in self.coordinate_paths:
            return self.coordinate_paths[path]
        name = reference.rstrip("/").split("/")[-1]
        if name in self.coordinate_paths.values():
            return name
        raise self.reader.error(elem, f"<{tag}> '{reference}' names no coordinate", expected="a coordinate of the model")

    # ------------------------------------------------------------------ tree
    def tree_order(self, joints: list[Joint]) -> list[Joint]:
        """Joints in OpenSim's multibody order: breadth-first levels from ground, file
        order within a level."""
        level = {GROUND: 0}
        remaining = list(joints)
        ordered: list[Joint] = []
        depth = 1
        while remaining:
            added = []
            for joint in remaining:
                if level.get(joint.parent_body) == depth - 1 and joint.child_body not in level:
                    added.append(joint)
                    level[joint.child_body] = depth
                elif level.get(joint.child_body) == depth - 1 and joint.parent_body not in level:
                    raise ModelError(
                        f"joint '{joint.name}' is reversed in the tree (its child '{joint.child_body}' is nearer "
                        "to ground than its parent)", file=self.file, element=f"{joint.type} '{joint.name}'",
                        expected="joints whose parents lead to ground")
            if not added:
                break
            ordered.extend(added)
            remaining = [j for j in remaining if j not in added]
            depth += 1
        if remaining:
            joint = remaining[0]
            reason = ("a second joint into an already connected body (closed loops are not supported)"
                      if joint.child_body in level else "not connected to ground")
            raise ModelError(f"joint '{joint.name}' is {reason}", file=self.file,
                             element=f"{joint.type} '{joint.name}'", expected="a tree of joints rooted at ground")
        return ordered

    # ------------------------------------------------------------------ constraints
    def parse_couplers(self, coordinate_names: set[str]) -> tuple[list[CoordinateCoupler], list[tuple[str, str]]]:
        r = self.reader
        couplers = []
        ignored = []
        for elem in r.elements(CONSTRAINT_TAGS_IGNORED):
            name = elem.get("name", "")
            if elem.tag != "CoordinateCouplerConstraint":
                if r.bool(elem, "isEnforced", True):
                    ignored.append((name, elem.tag))
                continue
            independent = r.names(elem, "independent_coordinate_names")
            dependent = r.text(elem, "dependent_coordinate_name")
            for cname in (*independent, dependent):
                if cname not in coordinate_names:
                    raise r.error(elem, f"names coordinate '{cname}', which the model does not have",
                                  expected="coordinates of the model")
            if len(independent) != 1:
                raise r.error(elem, f"has {len(independent)} independent coordinates",
                              expected="exactly one independent coordinate (multi-coordinate couplers are not supported)")
            func_elem = find_function(elem.find("coupled_coordinates_function"))
            if func_elem is None:
                raise r.error(elem, "has no coupled_coordinates_function", expected="a function")
            couplers.append(CoordinateCoupler(
                name, dependent, tuple(independent),
                parse_function(func_elem, file=self.file, owner=f"CoordinateCouplerConstraint '{name}'"),
                r.float(elem, "scale_factor", 1.0), r.bool(elem, "isEnforced", True)))
        dependents = [c.dependent for c in couplers if c.enforced]
        if len(set(dependents)) != len(dependents):
            raise ModelError("a coordinate is the dependent of two couplers", file=self.file,
                             element="ConstraintSet", expected="one coupler per dependent coordinate")
        for c in couplers:
            if c.enforced and c.independent[0] in dependents:
                raise ModelError(f"coupler '{c.name}' is driven by another coupler's dependent coordinate",
                                 file=self.file, element=f"CoordinateCouplerConstraint '{c.name}'",
                                 expected="independent coordinates that are not coupled")
        return couplers, ignored

    # ------------------------------------------------------------------ markers, wraps
    def parse_markers(self) -> list[Marker]:
        r = self.reader
        markers = []
        for elem in r.elements(["Marker"]):
            frame, body = self.frame_of(elem, "socket_parent_frame", component_path(elem))
            markers.append(Marker(elem.get("name", ""), frame, body,
                                  r.floats(elem, "location", [0, 0, 0], size=3), r.bool(elem, "fixed", False)))
        names = [m.name for m in markers]
        duplicates = sorted({n for n in names if names.count(n) > 1})
        if duplicates:
            raise ModelError(f"marker names used twice: {', '.join(duplicates)}", file=self.file,
                             element="MarkerSet", expected="unique marker names")
        return markers

    def parse_wrap_objects(self) -> list[WrapObject]:
        r = self.reader
        wraps = []
        for elem in r.elements(WRAP_TAGS):
            if elem.tag not in ("WrapCylinder", "WrapEllipsoid", "WrapSphere", "WrapTorus"):
                raise r.error(elem, f"wrap object type '{elem.tag}' is not supported",
                              expected="WrapCylinder, WrapEllipsoid, WrapSphere or WrapTorus")
            owner = next((a for a in elem.iterancestors() if a.tag in FRAME_TAGS), None)
            if owner is None:
                raise r.error(elem, "wrap object outside a frame", expected="a wrap object in a body's WrapObjectSet")
            frame_path = component_path(owner)
            if elem.tag == "WrapCylinder":
                params = {"radius": r.float(elem, "radius", 1.0), "length": r.float(elem, "length", 1.0)}
            elif elem.tag == "WrapEllipsoid":
                params = {"dimensions": r.floats(elem, "dimensions", [1.0, 1.0, 1.0], size=3)}
            elif elem.tag == "WrapSphere":
                params = {"radius": r.float(elem, "radius", 1.0)}
            else:
                params = {"inner_radius": r.float(elem, "inner_radius", 1.0),
                          "outer_radius": r.float(elem, "outer_radius", 1.0)}
            wraps.append(WrapObject(
                elem.get("name", ""), elem.tag, frame_path, self.frames[frame_path].base_body,
                r.bool(elem, "active", True), r.floats(elem, "xyz_body_rotation", [0, 0, 0], size=3),
                r.floats(elem, "translation", [0, 0, 0], size=3), r.text(elem, "quadrant", "all") or "all", params))
        return wraps


def _custom_motion_type(coordinate: str, axes: tuple[TransformAxis, ...]) -> str:
    """OpenSim's rule: a coordinate driving an axis through a LinearFunction of slope +-1 is
    rotational/translational (the last such axis decides); otherwise coupled."""
    motion = None
    for index, axis in enumerate(axes):
        if coordinate not in axis.coordinates:
            continue
        f = axis.function
        if isinstance(f, LinearFunction) and f.slope in (1.0, -1.0):
            motion = "rotational" if index < 3 else "translational"
        elif motion is None:
            motion = "coupled"
    return motion or "coupled"


#: characters OpenSim forbids in a component name (the path separator among them)
INVALID_NAME_CHARACTERS = "/\\"


def _check_component_names(r: XmlReader) -> None:
    """Refuse a component name holding a character OpenSim forbids (``/`` separates the parts
    of a component path; names also become parts of output file names)."""
    for elem in r.model.iter():
        name = elem.get("name") if isinstance(elem.tag, str) else None
        if name and any(c in name for c in INVALID_NAME_CHARACTERS):
            raise r.error(elem, f"the name '{name}' holds '/' or '\\', which OpenSim forbids in component names",
                          expected="a name without '/' or '\\' (e.g. '_' instead)")


def parse_model_document(root: etree._Element, file: str | Path, *, version: int = 0,
                         source_file: str | Path | None = None) -> Model:
    """The model in the XML tree ``root`` (an ``OpenSimDocument`` or ``Model`` element).

    ``file`` is the path used in error messages; ``source_file`` the file actually read.
    """
    parser = _Parser(root, str(file))
    r = parser.reader
    _check_component_names(r)
    parser.parse_frames()
    bodies = parser.parse_bodies()
    joints, coordinates = parser.parse_joints()
    joints = parser.tree_order(joints)
    joined = {j.child_body for j in joints}
    for name in bodies:
        if name not in joined:
            raise ModelError(f"body '{name}' has no joint", file=str(file), element=f"Body '{name}'",
                             expected="every body connected to the tree by a joint")
    couplers, ignored = parser.parse_couplers({c.name for c in coordinates})
    for name, tag in ignored:
        warnings.warn(f"{file}: {tag} '{name}' is ignored by nmsm's kinematics (only CoordinateCouplerConstraint "
                      "is modeled; OpenSim's inverse dynamics ignores constraints too)", stacklevel=2)
    markers = parser.parse_markers()
    wraps = parser.parse_wrap_objects()
    for wrap in wraps:
        body = bodies.get(wrap.body)
        if body is not None:
            body.wrap_objects.append(wrap)
    model = Model(
        name=r.model.get("name", ""),
        file=str(file),
        gravity=r.floats(r.model, "gravity", [0.0, -9.80665, 0.0], size=3),
        frames=parser.frames,
        bodies=bodies,
        joints=joints,
        coordinates=coordinates,
        couplers=couplers,
        markers=markers,
        wrap_objects={w.name: w for w in wraps},
        ignored_constraints=ignored,
        source_file=str(source_file or file),
        version=version,
    )
    for elem in r.elements(MUSCLE_TAGS | ACTUATOR_TAGS | OTHER_FORCE_TAGS | {"SmoothSphereHalfSpaceForce"}):
        if elem.tag in MUSCLE_TAGS:
            model.muscles.append(parse_muscle(r, elem, parser.frame_of, parser.coordinate_of))
        elif elem.tag in ACTUATOR_TAGS:
            model.actuators.append(parse_actuator(r, elem, parser.body_of, parser.coordinate_of))
        elif elem.tag == "SmoothSphereHalfSpaceForce":
            model.contact_forces.append(parse_smooth_contact(r, elem))
        else:
            model.other_forces.append(other_force(r, elem))
    for elem in r.elements(CONTACT_GEOMETRY_TAGS):
        geometry = parse_contact_geometry(r, elem, parser.frame_of)
        model.contact_geometry[component_path(elem)] = geometry
    for force in model.contact_forces:
        for path in (force.sphere, force.half_space):
            if path not in model.contact_geometry:
                raise ModelError(f"contact force '{force.name}' names missing contact geometry '{path}'",
                                 file=str(file), element=f"SmoothSphereHalfSpaceForce '{force.name}'",
                                 expected="a ContactSphere and a ContactHalfSpace of the model")
    model.groups = parse_groups(r)
    return model

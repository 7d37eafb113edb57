"""Parsing an ``.osim`` document's forces: muscles (with their GeometryPath), actuators,
contact geometry and contact forces, force groups. Components are found anywhere in the
model (ForceSet, ``<components>``, ...), not only in the ForceSet.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from lxml import etree

from nmsm.model.components import (
    ConditionalPathPoint,
    ContactGeometry,
    CoordinateActuator,
    GeometryPath,
    MovingPathPoint,
    Muscle,
    OtherForce,
    PathPoint,
    PathWrap,
    PointActuator,
    SmoothSphereHalfSpaceForce,
    TorqueActuator,
)
from nmsm.model.functions import find_function, parse_function
from nmsm.model.xml_tree import XmlReader, component_path, resolve_path

MUSCLE_TAGS = frozenset(
    {"Millard2012EquilibriumMuscle", "Millard2012AccelerationMuscle", "Thelen2003Muscle",
     "DeGrooteFregly2016Muscle", "RigidTendonMuscle", "Schutte1993Muscle_Deprecated",
     "Delp1990Muscle_Deprecated"}
)
ACTUATOR_TAGS = frozenset({"CoordinateActuator", "PointActuator", "TorqueActuator"})
CONTACT_GEOMETRY_TAGS = frozenset({"ContactSphere", "ContactHalfSpace", "ContactMesh", "ContactEllipsoid"})
#: force elements that nmsm knows by name but does not model (listed in Model.other_forces)
OTHER_FORCE_TAGS = frozenset(
    {"CoordinateLimitForce", "SpringGeneralizedForce", "ExpressionBasedCoordinateForce",
     "ExpressionBasedPointToPointForce", "ExpressionBasedBushingForce", "BushingForce",
     "PointToPointSpring", "Ligament", "PathSpring", "PathActuator", "McKibbenActuator",
     "HuntCrossleyForce", "ElasticFoundationForce", "PrescribedForce", "ExternalForce",
     "ClutchedPathSpring", "FunctionBasedBushingForce", "TwoFrameLinker", "ActivationCoordinateActuator",
     "MeyerFregly2016Force", "ContinuousTransition", "SmoothSphereHalfSpaceForce_Deprecated",
     "StationPlaneContactForce", "AckermannVanDenBogert2010Force", "EspositoMiller2018Force",
     "CoordinateLinearDamper", "CoordinateLinearStop", "PolynomialPathFitter"}
)

#: OpenSim's defaults for the common muscle properties
MUSCLE_DEFAULTS = {
    "max_isometric_force": 1000.0,
    "optimal_fiber_length": 0.1,
    "tendon_slack_length": 0.2,
    "pennation_angle_at_optimal": 0.0,
    "max_contraction_velocity": 10.0,
}

FrameResolver = Callable[[etree._Element, str, str], tuple[str, str]]
CoordinateResolver = Callable[[etree._Element, str], str]


def parse_geometry_path(
    reader: XmlReader, elem: etree._Element, owner: str, frame_of: FrameResolver,
    coordinate_of: CoordinateResolver,
) -> GeometryPath:
    """The path points and wrap references of a GeometryPath element (``owner`` names the
    muscle). ``frame_of(elem, socket_tag, owner_path)`` returns ``(frame path, base body)``."""
    path = GeometryPath()
    point_set = elem.find("PathPointSet")
    objects = point_set.find("objects") if point_set is not None else None
    for point in (objects if objects is not None else []):
        if not isinstance(point.tag, str):
            continue
        name = point.get("name", "")
        point_path = component_path(point)
        frame, body = frame_of(point, "socket_parent_frame", point_path)
        location = reader.floats(point, "location", [0.0, 0.0, 0.0], size=3)
        if point.tag == "PathPoint":
            path.points.append(PathPoint(name, frame, body, location))
        elif point.tag == "ConditionalPathPoint":
            coordinate = coordinate_of(point, "socket_coordinate")
            rng = reader.floats(point, "range", [-np.inf, np.inf], size=2)
            path.points.append(ConditionalPathPoint(name, frame, body, location, coordinate=coordinate,
                                                    range=(float(rng[0]), float(rng[1]))))
        elif point.tag == "MovingPathPoint":
            functions = []
            coordinates = []
            for axis in "xyz":
                holder = point.find(f"{axis}_location")
                func_elem = find_function(holder)
                if func_elem is None:
                    functions.append(None)
                    coordinates.append(None)
                    continue
                functions.append(parse_function(func_elem, file=reader.file, owner=f"{owner} {name} {axis}_location"))
                coordinates.append(coordinate_of(point, f"socket_{axis}_coordinate"))
            path.points.append(MovingPathPoint(name, frame, body, location, functions=tuple(functions),
                                               coordinates=tuple(coordinates)))
        else:
            raise reader.error(point, f"path point type '{point.tag}' of muscle '{owner}' is not supported",
                               expected="PathPoint, ConditionalPathPoint or MovingPathPoint")
    wrap_set = elem.find("PathWrapSet")
    objects = wrap_set.find("objects") if wrap_set is not None else None
    for wrap in (objects if objects is not None else []):
        if not isinstance(wrap.tag, str):
            continue
        if wrap.tag != "PathWrap":
            raise reader.error(wrap, f"wrap entry '{wrap.tag}' of muscle '{owner}' is not supported",
                               expected="PathWrap")
        rng = reader.floats(wrap, "range", [-1, -1], size=2)
        path.wraps.append(PathWrap(reader.text(wrap, "wrap_object", "") or "",
                                   reader.text(wrap, "method", "hybrid") or "hybrid",
                                   (int(rng[0]), int(rng[1]))))
    return path


def _simple_properties(elem: etree._Element) -> dict[str, str]:
    out: dict[str, str] = {}
    for child in elem:
        if isinstance(child.tag, str) and len(child) == 0 and child.text is not None:
            out[child.tag] = child.text.strip()
    return out


def _curve_properties(elem: etree._Element) -> dict[str, str]:
    out: dict[str, str] = {}
    for child in elem:
        if not isinstance(child.tag, str) or not child.tag.endswith("Curve"):
            continue
        for prop in child:
            if isinstance(prop.tag, str) and len(prop) == 0 and prop.text is not None:
                out[f"{child.tag}/{prop.tag}"] = prop.text.strip()
    return out


def parse_muscle(reader: XmlReader, elem: etree._Element, frame_of: FrameResolver,
                 coordinate_of: CoordinateResolver) -> Muscle:
    name = elem.get("name", "")
    geometry_elem = elem.find("GeometryPath")
    if geometry_elem is None:
        raise reader.error(elem, "muscle has no GeometryPath", expected="<GeometryPath> with path points")
    values = {key: reader.float(elem, key, default) for key, default in MUSCLE_DEFAULTS.items()}
    return Muscle(
        name=name,
        type=elem.tag,
        path=component_path(elem),
        applies_force=reader.bool(elem, "appliesForce", True),
        geometry=parse_geometry_path(reader, geometry_elem, name, frame_of, coordinate_of),
        properties=_simple_properties(elem),
        curves=_curve_properties(elem),
        **values,
    )


def parse_actuator(reader: XmlReader, elem: etree._Element, body_of: Callable[[etree._Element, str], str],
                   coordinate_of: CoordinateResolver):
    name = elem.get("name", "")
    common = dict(
        min_control=reader.float(elem, "min_control", -np.inf),
        max_control=reader.float(elem, "max_control", np.inf),
        applies_force=reader.bool(elem, "appliesForce", True),
    )
    if elem.tag == "CoordinateActuator":
        return CoordinateActuator(name, coordinate_of(elem, "coordinate"),
                                  reader.float(elem, "optimal_force", 1.0), **common)
    if elem.tag == "PointActuator":
        return PointActuator(
            name, body_of(elem, "body"), reader.floats(elem, "point", [0, 0, 0], size=3),
            reader.bool(elem, "point_is_global", False),
            reader.floats(elem, "direction", [1, 0, 0], size=3),
            reader.bool(elem, "force_is_global", False), reader.float(elem, "optimal_force", 1.0), **common)
    return TorqueActuator(
        name, body_of(elem, "bodyA"), body_of(elem, "bodyB"),
        reader.floats(elem, "axis", [0, 0, 1], size=3), reader.bool(elem, "torque_is_global", True),
        reader.float(elem, "optimal_force", 1.0), **common)


def parse_contact_geometry(reader: XmlReader, elem: etree._Element, frame_of: FrameResolver) -> ContactGeometry:
    if elem.tag not in ("ContactSphere", "ContactHalfSpace"):
        raise reader.error(elem, f"contact geometry type '{elem.tag}' is not supported",
                           expected="ContactSphere or ContactHalfSpace")
    frame, body = frame_of(elem, "socket_frame", component_path(elem))
    radius = reader.float(elem, "radius", 0.0) if elem.tag == "ContactSphere" else 0.0
    return ContactGeometry(
        elem.get("name", ""), elem.tag, frame, body,
        reader.floats(elem, "location", [0, 0, 0], size=3),
        reader.floats(elem, "orientation", [0, 0, 0], size=3), radius,
    )


def parse_smooth_contact(reader: XmlReader, elem: etree._Element) -> SmoothSphereHalfSpaceForce:
    owner = component_path(elem)
    sphere = reader.text(elem, "socket_sphere")
    half_space = reader.text(elem, "socket_half_space")
    if not sphere or not half_space:
        raise reader.error(elem, "contact force without sphere or half space",
                           expected="<socket_sphere> and <socket_half_space>")
    defaults = SmoothSphereHalfSpaceForce("", "", "")
    values = {
        key: reader.float(elem, key, getattr(defaults, key))
        for key in ("stiffness", "dissipation", "static_friction", "dynamic_friction", "viscous_friction",
                    "transition_velocity", "constant_contact_force", "hertz_smoothing",
                    "hunt_crossley_smoothing")
    }
    return SmoothSphereHalfSpaceForce(
        elem.get("name", ""), resolve_path(sphere, owner), resolve_path(half_space, owner),
        applies_force=reader.bool(elem, "appliesForce", True), **values,
    )


def parse_groups(reader: XmlReader) -> dict[str, list[str]]:
    """ForceSet groups: group name -> member names (in file order)."""
    groups: dict[str, list[str]] = {}
    for force_set in reader.elements(["ForceSet"]):
        holder = force_set.find("groups")
        for group in (holder if holder is not None else []):
            if isinstance(group.tag, str) and group.tag == "ObjectGroup":
                groups[group.get("name", "")] = list(reader.names(group, "members"))
    return groups


def other_force(reader: XmlReader, elem: etree._Element) -> OtherForce:
    return OtherForce(elem.get("name", ""), elem.tag, reader.bool(elem, "appliesForce", True))

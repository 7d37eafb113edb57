"""Data classes of a parsed OpenSim model (no CasADi, no OpenSim).

Units: lengths in m, angles in rad, masses in kg, inertias in kg m^2, forces in N.
Vectors are numpy arrays of shape ``(3,)``, rotation matrices ``(3, 3)``.

Frames are referred to by their component path (``/bodyset/femur_r``,
``/jointset/knee_r/femur_r_offset``, ``/ground``); every frame resolves to the body it is
fixed to (its *base body*, ``"ground"`` for ground) and its fixed pose in that body.
"""

from __future__ import annotations

from typing import Literal

import attrs
import numpy as np

from nmsm.model.functions import Function

Vector3 = np.ndarray

GROUND = "ground"

MotionType = Literal["rotational", "translational", "coupled"]


def _vec3(value: object) -> np.ndarray:
    return np.asarray(value, dtype=float).reshape(3)


@attrs.define(eq=False)
class Frame:
    """A frame: ground, a body, or a PhysicalOffsetFrame.

    ``translation`` and ``orientation`` (body-fixed X-Y-Z angles, rad) place an offset frame in
    its ``parent`` frame (a path); both are zero for bodies and ground. ``base_body`` is the
    body (or ``"ground"``) the frame is rigidly attached to; ``rotation_in_base`` /
    ``origin_in_base`` give its numeric pose there (for the values in the file).
    """

    name: str
    path: str
    kind: Literal["ground", "body", "offset"]
    parent: str | None = None
    translation: Vector3 = attrs.field(factory=lambda: np.zeros(3), converter=_vec3)
    orientation: Vector3 = attrs.field(factory=lambda: np.zeros(3), converter=_vec3)
    base_body: str = ""
    rotation_in_base: np.ndarray = attrs.field(factory=lambda: np.eye(3))
    origin_in_base: Vector3 = attrs.field(factory=lambda: np.zeros(3), converter=_vec3)
    xml_line: int | None = None


@attrs.define(eq=False)
class WrapObject:
    """A wrap surface fixed to a frame (WrapCylinder, WrapEllipsoid, WrapSphere, WrapTorus).

    ``parameters`` holds the type's dimensions: ``radius``, ``length`` (cylinder);
    ``dimensions`` (ellipsoid semi-axes, shape (3,)); ``radius`` (sphere); ``inner_radius``,
    ``outer_radius`` (torus). ``rotation`` is body-fixed X-Y-Z angles (rad), ``translation``
    the origin, both in ``frame``; ``body`` is the base body of ``frame``.
    """

    name: str
    type: str
    frame: str
    body: str
    active: bool
    rotation: Vector3 = attrs.field(converter=_vec3)
    translation: Vector3 = attrs.field(converter=_vec3)
    quadrant: str = "all"
    parameters: dict[str, object] = attrs.field(factory=dict)


@attrs.define(eq=False)
class Body:
    """A rigid body: ``mass`` (kg), ``mass_center`` (m, body frame), ``inertia`` (3x3 about the
    centre of mass, body axes, kg m^2)."""

    name: str
    path: str
    mass: float
    mass_center: Vector3 = attrs.field(converter=_vec3)
    inertia: np.ndarray = attrs.field(factory=lambda: np.zeros((3, 3)))
    wrap_objects: list[WrapObject] = attrs.field(factory=list)


@attrs.define(eq=False)
class Coordinate:
    """A generalized coordinate of a joint (rad or m, by ``motion_type``)."""

    name: str
    joint: str
    motion_type: MotionType
    range: tuple[float, float]
    default_value: float = 0.0
    default_speed: float = 0.0
    locked: bool = False
    clamped: bool = False
    prescribed: bool = False

    @property
    def is_rotational(self) -> bool:
        return self.motion_type == "rotational"


@attrs.define(eq=False)
class TransformAxis:
    """One of a CustomJoint's six axes: ``rotation1..3`` then ``translation1..3``.

    The axis value is ``function(coordinate)`` (rad or m); a constant function has no
    coordinate. ``axis`` is the unit direction in the joint's parent frame (rotations are
    successive body-fixed rotations about the axes in order).
    """

    name: str
    coordinates: tuple[str, ...]
    axis: Vector3 = attrs.field(converter=_vec3)
    function: Function | None = None

    @property
    def is_rotation(self) -> bool:
        return self.name.startswith("rotation")


JOINT_TYPES = (
    "CustomJoint", "PinJoint", "WeldJoint", "UniversalJoint", "FreeJoint", "PlanarJoint",
    "SliderJoint", "BallJoint", "GimbalJoint",
)


@attrs.define(eq=False)
class Joint:
    """A joint between a parent frame and a child frame (paths into :attr:`Model.frames`).

    ``coordinates`` lists the joint's coordinate names in OpenSim's order (for a CustomJoint:
    order of first appearance in the SpatialTransform). ``transform_axes`` holds the six
    axes of a CustomJoint (empty for other types).
    """

    name: str
    type: str
    path: str
    parent_frame: str
    child_frame: str
    parent_body: str
    child_body: str
    coordinates: tuple[str, ...] = ()
    transform_axes: tuple[TransformAxis, ...] = ()
    xml_line: int | None = None


@attrs.define(eq=False)
class CoordinateCoupler:
    """``dependent = scale_factor * function(independent...)`` (CoordinateCouplerConstraint)."""

    name: str
    dependent: str
    independent: tuple[str, ...]
    function: Function
    scale_factor: float = 1.0
    enforced: bool = True


@attrs.define(eq=False)
class Marker:
    """A marker at ``location`` (m) in ``frame``; ``body`` is the frame's base body."""

    name: str
    frame: str
    body: str
    location: Vector3 = attrs.field(converter=_vec3)
    fixed: bool = False


@attrs.define(eq=False)
class PathPoint:
    """A fixed path point at ``location`` (m) in ``frame`` (base body ``body``)."""

    name: str
    frame: str
    body: str
    location: Vector3 = attrs.field(converter=_vec3)


@attrs.define(eq=False)
class ConditionalPathPoint(PathPoint):
    """A path point active only while ``coordinate`` lies within ``range`` (inclusive)."""

    coordinate: str = ""
    range: tuple[float, float] = (0.0, 0.0)


@attrs.define(eq=False)
class MovingPathPoint(PathPoint):
    """A path point whose x, y, z (m, in ``frame``) are functions of coordinates.

    ``functions[i]`` gives component i as a function of ``coordinates[i]``; a component
    without a function (None) keeps ``location[i]``.
    """

    functions: tuple[Function | None, Function | None, Function | None] = (None, None, None)
    coordinates: tuple[str | None, str | None, str | None] = (None, None, None)


@attrs.define(eq=False)
class PathWrap:
    """A reference from a path to a wrap object, with method and point range (1-based, -1 = all)."""

    wrap_object: str
    method: str = "hybrid"
    range: tuple[int, int] = (-1, -1)


@attrs.define(eq=False)
class GeometryPath:
    """A muscle's path: points in order, wrap references in order."""

    points: list[PathPoint] = attrs.field(factory=list)
    wraps: list[PathWrap] = attrs.field(factory=list)


@attrs.define(eq=False)
class Muscle:
    """A Hill-type muscle (Millard2012EquilibriumMuscle, Thelen2003Muscle,
    DeGrooteFregly2016Muscle, ...).

    The common parameters are attributes (N, m, rad, optimal fibre lengths per second);
    ``properties`` holds every other simple (text) property of the element by tag, for
    the muscle model; ``curves`` the raw text of nested curve parameters by
    ``"<CurveTag>/<property>"``.
    """

    name: str
    type: str
    path: str
    max_isometric_force: float
    optimal_fiber_length: float
    tendon_slack_length: float
    pennation_angle_at_optimal: float
    max_contraction_velocity: float
    applies_force: bool
    geometry: GeometryPath
    properties: dict[str, str] = attrs.field(factory=dict)
    curves: dict[str, str] = attrs.field(factory=dict)


@attrs.define(eq=False)
class CoordinateActuator:
    """Generalized force ``optimal_force * control`` on ``coordinate``."""

    name: str
    coordinate: str
    optimal_force: float
    min_control: float
    max_control: float
    applies_force: bool = True


@attrs.define(eq=False)
class PointActuator:
    """Force ``optimal_force * control * direction`` at ``point`` on ``body``.

    ``point_is_global``: point given in ground (else in the body frame);
    ``force_is_global``: direction given in ground (else in the body frame).
    """

    name: str
    body: str
    point: Vector3 = attrs.field(converter=_vec3)
    point_is_global: bool = False
    direction: Vector3 = attrs.field(factory=lambda: np.array([1.0, 0.0, 0.0]), converter=_vec3)
    force_is_global: bool = False
    optimal_force: float = 1.0
    min_control: float = -np.inf
    max_control: float = np.inf
    applies_force: bool = True


@attrs.define(eq=False)
class TorqueActuator:
    """Torque ``optimal_force * control * axis`` on ``body_a`` and its opposite on ``body_b``.

    ``torque_is_global``: axis given in ground (else in body_a's frame).
    """

    name: str
    body_a: str
    body_b: str
    axis: Vector3 = attrs.field(factory=lambda: np.array([0.0, 0.0, 1.0]), converter=_vec3)
    torque_is_global: bool = True
    optimal_force: float = 1.0
    min_control: float = -np.inf
    max_control: float = np.inf
    applies_force: bool = True


Actuator = CoordinateActuator | PointActuator | TorqueActuator


@attrs.define(eq=False)
class ContactGeometry:
    """ContactSphere (``radius``) or ContactHalfSpace (occupies x > 0 of its own frame, so its
    surface normal pointing into the half space is the frame's +x axis).

    ``location`` (m) and ``orientation`` (body-fixed X-Y-Z, rad) place the geometry in ``frame``.
    """

    name: str
    type: Literal["ContactSphere", "ContactHalfSpace"]
    frame: str
    body: str
    location: Vector3 = attrs.field(converter=_vec3)
    orientation: Vector3 = attrs.field(converter=_vec3)
    radius: float = 0.0


@attrs.define(eq=False)
class SmoothSphereHalfSpaceForce:
    """Smooth Hunt-Crossley sphere-plane contact with smooth Stribeck friction (OpenSim 4)."""

    name: str
    sphere: str
    half_space: str
    stiffness: float = 1.0
    dissipation: float = 0.0
    static_friction: float = 0.0
    dynamic_friction: float = 0.0
    viscous_friction: float = 0.0
    transition_velocity: float = 0.01
    constant_contact_force: float = 1e-5
    hertz_smoothing: float = 300.0
    hunt_crossley_smoothing: float = 50.0
    applies_force: bool = True


@attrs.define(eq=False)
class OtherForce:
    """A force element nmsm does not model (kept so tools can report it)."""

    name: str
    type: str
    applies_force: bool


@attrs.define(eq=False)
class Model:
    """An OpenSim model read from a ``.osim`` file.

    Containers are ordered as in the file; ``joints`` is in tree order (every joint's parent
    body appears before its child body; OpenSim's multibody order). ``coordinates`` is in
    OpenSim's CoordinateSet order (joints in file order, each joint's coordinates in order).
    ``groups`` maps ForceSet group names to member names ("muscle groups").
    ``ignored_constraints`` lists (name, type) of enforced constraints other than couplers,
    which nmsm's kinematics do not model. ``file`` is the path the user gave; ``source_file``
    the file actually read (an upgraded copy for old file versions).
    """

    name: str
    file: str
    gravity: Vector3 = attrs.field(converter=_vec3)
    frames: dict[str, Frame] = attrs.field(factory=dict)
    bodies: dict[str, Body] = attrs.field(factory=dict)
    joints: list[Joint] = attrs.field(factory=list)
    coordinates: list[Coordinate] = attrs.field(factory=list)
    couplers: list[CoordinateCoupler] = attrs.field(factory=list)
    markers: list[Marker] = attrs.field(factory=list)
    muscles: list[Muscle] = attrs.field(factory=list)
    actuators: list[Actuator] = attrs.field(factory=list)
    contact_geometry: dict[str, ContactGeometry] = attrs.field(factory=dict)
    contact_forces: list[SmoothSphereHalfSpaceForce] = attrs.field(factory=list)
    other_forces: list[OtherForce] = attrs.field(factory=list)
    groups: dict[str, list[str]] = attrs.field(factory=dict)
    wrap_objects: dict[str, WrapObject] = attrs.field(factory=dict)
    ignored_constraints: list[tuple[str, str]] = attrs.field(factory=list)
    source_file: str = ""
    version: int = 0

    # ------------------------------------------------------------------ lookups
    @property
    def coordinate_names(self) -> list[str]:
        return [c.name for c in self.coordinates]

    @property
    def marker_names(self) -> list[str]:
        return [m.name for m in self.markers]

    @property
    def muscle_names(self) -> list[str]:
        return [m.name for m in self.muscles]

    @property
    def body_names(self) -> list[str]:
        return list(self.bodies)

    def coordinate(self, name: str) -> Coordinate:
        for c in self.coordinates:
            if c.name == name:
                return c
        raise KeyError(f"model '{self.name}' ({self.file}) has no coordinate '{name}'")

    def coordinate_index(self, name: str) -> int:
        for i, c in enumerate(self.coordinates):
            if c.name == name:
                return i
        raise KeyError(f"model '{self.name}' ({self.file}) has no coordinate '{name}'")

    def joint(self, name: str) -> Joint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(f"model '{self.name}' ({self.file}) has no joint '{name}'")

    def marker(self, name: str) -> Marker:
        for m in self.markers:
            if m.name == name:
                return m
        raise KeyError(f"model '{self.name}' ({self.file}) has no marker '{name}'")

    def muscle(self, name: str) -> Muscle:
        for m in self.muscles:
            if m.name == name:
                return m
        raise KeyError(f"model '{self.name}' ({self.file}) has no muscle '{name}'")

    def group_members(self, group: str) -> list[str]:
        try:
            return list(self.groups[group])
        except KeyError:
            raise KeyError(f"model '{self.name}' ({self.file}) has no force group '{group}' "
                           f"(groups: {', '.join(self.groups) or 'none'})") from None

    @property
    def coupled_coordinates(self) -> dict[str, CoordinateCoupler]:
        """Dependent coordinate name -> its (enforced) coupler."""
        return {c.dependent: c for c in self.couplers if c.enforced}

    @property
    def independent_coordinate_names(self) -> list[str]:
        """Coordinates that are not the dependent side of an enforced coupler."""
        dependent = self.coupled_coordinates
        return [c.name for c in self.coordinates if c.name not in dependent]

    @property
    def tree_coordinate_names(self) -> list[str]:
        """Coordinates in multibody tree order (the column order of OpenSim's ID output)."""
        joints = {j.name: j for j in self.joints}
        order: list[str] = []
        for joint in self.joints:
            order.extend(joints[joint.name].coordinates)
        return order

    def total_mass(self) -> float:
        return float(sum(b.mass for b in self.bodies.values()))

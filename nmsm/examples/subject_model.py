"""The built-in synthetic subject's OpenSim model, written in code.

A pelvis (6 coordinates) and a right leg: hip (flexion, adduction, rotation), knee
(flexion positive), ankle (dorsiflexion positive) and a two-segment foot (``calcn_r``
hindfoot, ``toes_r`` on the ``mtp_angle_r`` joint). Eight path-point Hill muscles
(Millard2012EquilibriumMuscle elements), one ForceSet group per EMG channel plus the
synergy group ``RightLeg``; 19 markers, among them the five foot markers Ground Contact
Personalization places its springs from.

Frames: x forward, y up, z to the right. Lengths m, masses kg, inertias kg m^2, angles
rad. In the default pose (all coordinates 0, ``pelvis_ty`` = :data:`STANDING_HEIGHT`) the
sole (``y = -SOLE_DEPTH`` in ``calcn_r``) is on the floor.

:func:`subject_model_xml` returns the file's bytes given the muscles' optimal fiber and
tendon slack lengths (:mod:`nmsm.examples.subject_truth` computes the true ones from the
path lengths); joint frames can be rotated (``frame_orientations``) to make the generic
model JMP starts from.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import attrs
import numpy as np
from lxml import etree

#: height of the ankle above the sole (m); hindfoot origin = ankle centre
SOLE_DEPTH = 0.075
#: thigh and shank lengths (m)
THIGH, SHANK = 0.42, 0.43
#: hip centre in the pelvis frame (m)
HIP = (-0.07, -0.07, 0.085)
#: toes joint in the hindfoot frame (m)
MTP_JOINT = (0.14, -0.06, 0.005)
#: pelvis height (m) that puts the sole on the floor in the default pose
STANDING_HEIGHT = -HIP[1] + THIGH + SHANK + SOLE_DEPTH
#: the coordinates, in model order
COORDINATES = ("pelvis_tilt", "pelvis_list", "pelvis_rotation", "pelvis_tx", "pelvis_ty", "pelvis_tz",
               "hip_flexion_r", "hip_adduction_r", "hip_rotation_r", "knee_angle_r", "ankle_angle_r", "mtp_angle_r")
#: coordinates the muscles act on (MTP, NCP and treatment track their moments)
MUSCLE_COORDINATES = ("hip_flexion_r", "knee_angle_r", "ankle_angle_r")

#: body -> (mass, centre of mass, principal moments of inertia)
BODIES: dict[str, tuple[float, tuple[float, float, float], tuple[float, float, float]]] = {
    "pelvis": (11.0, (-0.07, 0.0, 0.0), (0.10, 0.09, 0.06)),
    "femur_r": (8.0, (0.0, -0.17, 0.0), (0.11, 0.03, 0.11)),
    "tibia_r": (3.5, (0.0, -0.18, 0.0), (0.05, 0.005, 0.05)),
    "calcn_r": (1.0, (0.05, -0.04, 0.0), (0.0014, 0.004, 0.0039)),
    "toes_r": (0.2, (0.03, -0.005, 0.0), (0.0001, 0.0002, 0.0001)),
}

#: marker -> (body, location)
MARKERS: dict[str, tuple[str, tuple[float, float, float]]] = {
    "R_ASIS": ("pelvis", (0.01, 0.0, 0.12)),
    "L_ASIS": ("pelvis", (0.01, 0.0, -0.12)),
    "SACRUM": ("pelvis", (-0.16, 0.03, 0.0)),
    "R_Thigh_Superior": ("femur_r", (0.05, -0.12, 0.05)),
    "R_Thigh_Lateral": ("femur_r", (0.0, -0.25, 0.075)),
    "R_Thigh_Anterior": ("femur_r", (0.06, -0.32, 0.02)),
    "R_Knee_Lateral": ("femur_r", (0.0, -0.42, 0.05)),
    "R_Knee_Medial": ("femur_r", (0.0, -0.42, -0.05)),
    "R_Shank_Superior": ("tibia_r", (0.04, -0.08, 0.04)),
    "R_Shank_Lateral": ("tibia_r", (-0.01, -0.20, 0.06)),
    "R_Shank_Anterior": ("tibia_r", (0.035, -0.30, 0.02)),
    "R_Ankle_Lateral": ("tibia_r", (0.0, -0.43, 0.055)),
    "R_Ankle_Medial": ("tibia_r", (0.0, -0.43, -0.045)),
    "R_Heel": ("calcn_r", (-0.06, -0.045, 0.0)),
    "R_Midfoot_Superior": ("calcn_r", (0.06, -0.005, 0.0)),
    "R_Midfoot_Lateral": ("calcn_r", (0.06, -0.05, 0.045)),
    "R_Toe_Medial": ("calcn_r", (0.14, -0.055, -0.035)),
    "R_Toe_Lateral": ("calcn_r", (0.12, -0.055, 0.045)),
    "R_Toe": ("toes_r", (0.06, -0.012, -0.005)),
}
#: Ground Contact Personalization's marker roles
FOOT_MARKERS = {"toe": "R_Toe", "medial": "R_Toe_Medial", "lateral": "R_Toe_Lateral", "heel": "R_Heel",
                "midfoot_superior": "R_Midfoot_Superior"}


@attrs.frozen
class MuscleSpec:
    """A muscle: EMG channel (its ForceSet group), path points ``(body, location)``, maximum
    isometric force (N), pennation at optimal length (rad), optimal fiber length (m)."""

    channel: str
    points: tuple[tuple[str, tuple[float, float, float]], ...]
    max_isometric_force: float
    pennation: float
    optimal_fiber_length: float


MUSCLES: dict[str, MuscleSpec] = {
    "iliacus_r": MuscleSpec("IL", (("pelvis", (-0.03, 0.03, 0.07)), ("pelvis", (-0.02, -0.08, 0.085)),
                                   ("femur_r", (0.005, -0.06, 0.0))), 6300.0, 0.12, 0.10),
    "glmax_r": MuscleSpec("GMAX", (("pelvis", (-0.15, 0.0, 0.06)), ("pelvis", (-0.13, -0.10, 0.095)),
                                   ("femur_r", (-0.03, -0.10, 0.03))), 4900.0, 0.10, 0.15),
    "recfem_r": MuscleSpec("RF", (("pelvis", (-0.03, -0.04, 0.095)), ("femur_r", (0.045, -0.38, 0.0)),
                                  ("tibia_r", (0.055, 0.0, 0.0)), ("tibia_r", (0.045, -0.07, 0.0))), 3500.0, 0.15, 0.08),
    "hamstrings_r": MuscleSpec("HAM", (("pelvis", (-0.12, -0.10, 0.07)), ("tibia_r", (-0.035, -0.05, 0.0))),
                               4480.0, 0.20, 0.10),
    "vasti_r": MuscleSpec("VAS", (("femur_r", (0.03, -0.20, 0.02)), ("femur_r", (0.045, -0.38, 0.0)),
                                  ("tibia_r", (0.055, 0.0, 0.0)), ("tibia_r", (0.045, -0.07, 0.0))), 7000.0, 0.07, 0.09),
    "gastroc_r": MuscleSpec("GAS", (("femur_r", (-0.02, -0.40, 0.0)), ("tibia_r", (-0.045, -0.15, 0.0)),
                                    ("calcn_r", (-0.05, 0.0, 0.0))), 4200.0, 0.25, 0.06),
    "soleus_r": MuscleSpec("SOL", (("tibia_r", (-0.02, -0.15, 0.0)), ("calcn_r", (-0.05, 0.0, 0.0))),
                           7700.0, 0.35, 0.05),
    "tibant_r": MuscleSpec("TA", (("tibia_r", (0.02, -0.15, 0.01)), ("tibia_r", (0.03, -0.40, 0.0)),
                                  ("calcn_r", (0.09, -0.02, -0.01))), 3500.0, 0.10, 0.07),
}
#: the synergy group (all muscles)
SYNERGY_GROUP = "RightLeg"


def _sub(parent: etree._Element, tag: str, text: str | None = None, **attributes: str) -> etree._Element:
    element = etree.SubElement(parent, tag, **attributes)
    if text is not None:
        element.text = text
    return element


def _vec(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _frame(frames: etree._Element, name: str, body: str, translation: Sequence[float],
           orientation: Sequence[float]) -> None:
    frame = _sub(frames, "PhysicalOffsetFrame", name=name)
    _sub(frame, "socket_parent", "/ground" if body == "ground" else f"/bodyset/{body}")
    _sub(frame, "translation", _vec(translation))
    _sub(frame, "orientation", _vec(orientation))


def _coordinate(coordinates: etree._Element, name: str, default: float, lower: float, upper: float,
                clamped: bool) -> None:
    c = _sub(coordinates, "Coordinate", name=name)
    _sub(c, "default_value", repr(float(default)))
    _sub(c, "default_speed_value", "0")
    _sub(c, "range", _vec((lower, upper)))
    _sub(c, "clamped", "true" if clamped else "false")
    _sub(c, "locked", "false")


def _axis(transform: etree._Element, name: str, coordinate: str | None, axis: Sequence[float]) -> None:
    ta = _sub(transform, "TransformAxis", name=name)
    _sub(ta, "coordinates", coordinate or "")
    _sub(ta, "axis", _vec(axis))
    if coordinate:
        _sub(_sub(ta, "LinearFunction", name="function"), "coefficients", "1 0")
    else:
        _sub(_sub(ta, "Constant", name="function"), "value", "0")


def _joint(joints: etree._Element, name: str, parent: str, child: str, translation: Sequence[float],
           orientations: Mapping[str, Sequence[float]], rotations: Sequence[tuple[str, Sequence[float], float, float]],
           translations: Sequence[tuple[str, Sequence[float], float, float, float]] = ()) -> None:
    """A CustomJoint: ``rotations`` (coordinate, axis, lower, upper), ``translations``
    (coordinate, unit axis, default, lower, upper); ``orientations`` of the parent/child frames."""
    joint = _sub(joints, "CustomJoint", name=name)
    _sub(joint, "socket_parent_frame", f"{parent}_offset")
    _sub(joint, "socket_child_frame", f"{child}_offset")
    coordinates = _sub(joint, "coordinates")
    for coordinate, _, lower, upper in rotations:
        _coordinate(coordinates, coordinate, 0.0, lower, upper, clamped=True)
    for coordinate, _, default, lower, upper in translations:
        _coordinate(coordinates, coordinate, default, lower, upper, clamped=False)
    frames = _sub(joint, "frames")
    _frame(frames, f"{parent}_offset", parent, translation, orientations.get("parent", (0, 0, 0)))
    _frame(frames, f"{child}_offset", child, (0, 0, 0), orientations.get("child", (0, 0, 0)))
    transform = _sub(joint, "SpatialTransform")
    defaults = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    # unused rotation axes must not be collinear with used ones (OpenSim refuses such joints)
    used = [np.abs(np.asarray(axis, dtype=float)) for _, axis, *_ in rotations]
    spare = iter(u for u in defaults if not any(np.allclose(np.asarray(u, dtype=float), a) for a in used))
    for k in range(3):
        coordinate, axis = (rotations[k][0], rotations[k][1]) if k < len(rotations) else (None, next(spare))
        _axis(transform, f"rotation{k + 1}", coordinate, axis)
    named = {tuple(axis): coordinate for coordinate, axis, *_ in translations}
    for k, unit in enumerate(defaults):
        _axis(transform, f"translation{k + 1}", named.get(unit), unit)


def subject_model_xml(optimal_fiber_lengths: Mapping[str, float], tendon_slack_lengths: Mapping[str, float],
                      frame_orientations: Mapping[tuple[str, str], Sequence[float]] | None = None,
                      name: str = "synthetic_subject") -> bytes:
    """The model file (see module docstring); ``frame_orientations[(joint, "parent"|"child")]``
    rotates a joint's offset frame (body-fixed X-Y-Z, rad)."""
    orientations: dict[str, dict[str, Sequence[float]]] = {}
    for (joint, which), value in (frame_orientations or {}).items():
        orientations.setdefault(joint, {})[which] = value
    root = etree.Element("OpenSimDocument", Version="40000")
    model = _sub(root, "Model", name=name)
    _sub(model, "Ground", name="ground")
    _sub(model, "gravity", "0 -9.8066499999999994 0")
    bodies = _sub(_sub(model, "BodySet", name="bodyset"), "objects")
    for body_name, (mass, com, inertia) in BODIES.items():
        body = _sub(bodies, "Body", name=body_name)
        _sub(body, "mass", repr(mass))
        _sub(body, "mass_center", _vec(com))
        _sub(body, "inertia", _vec((*inertia, 0, 0, 0)))
    joints = _sub(_sub(model, "JointSet", name="jointset"), "objects")
    half_pi = np.pi / 2
    _joint(joints, "ground_pelvis", "ground", "pelvis", (0, 0, 0), orientations.get("ground_pelvis", {}),
           [("pelvis_tilt", (0, 0, 1), -half_pi, half_pi), ("pelvis_list", (1, 0, 0), -half_pi, half_pi),
            ("pelvis_rotation", (0, 1, 0), -half_pi, half_pi)],
           [("pelvis_tx", (1, 0, 0), 0.0, -5.0, 5.0), ("pelvis_ty", (0, 1, 0), STANDING_HEIGHT, -1.0, 2.0),
            ("pelvis_tz", (0, 0, 1), 0.0, -3.0, 3.0)])
    _joint(joints, "hip_r", "pelvis", "femur_r", HIP, orientations.get("hip_r", {}),
           [("hip_flexion_r", (0, 0, 1), -0.5, 2.0), ("hip_adduction_r", (1, 0, 0), -0.8, 0.5),
            ("hip_rotation_r", (0, 1, 0), -0.7, 0.7)])
    _joint(joints, "knee_r", "femur_r", "tibia_r", (0, -THIGH, 0), orientations.get("knee_r", {}),
           [("knee_angle_r", (0, 0, -1), -0.1, 2.1)])
    _joint(joints, "ankle_r", "tibia_r", "calcn_r", (0, -SHANK, 0), orientations.get("ankle_r", {}),
           [("ankle_angle_r", (0, 0, 1), -0.7, 0.6)])
    _joint(joints, "mtp_r", "calcn_r", "toes_r", MTP_JOINT, orientations.get("mtp_r", {}),
           [("mtp_angle_r", (0, 0, 1), -0.6, 1.0)])
    force_set = _sub(model, "ForceSet", name="forceset")
    forces = _sub(force_set, "objects")
    for muscle_name, spec in MUSCLES.items():
        muscle = _sub(forces, "Millard2012EquilibriumMuscle", name=muscle_name)
        _sub(muscle, "appliesForce", "true")
        path = _sub(muscle, "GeometryPath", name="path")
        points = _sub(_sub(path, "PathPointSet"), "objects")
        for k, (body, location) in enumerate(spec.points, start=1):
            point = _sub(points, "PathPoint", name=f"{muscle_name}-P{k}")
            _sub(point, "socket_parent_frame", f"/bodyset/{body}")
            _sub(point, "location", _vec(location))
        _sub(muscle, "max_isometric_force", repr(spec.max_isometric_force))
        _sub(muscle, "optimal_fiber_length", repr(float(optimal_fiber_lengths[muscle_name])))
        _sub(muscle, "tendon_slack_length", repr(float(tendon_slack_lengths[muscle_name])))
        _sub(muscle, "pennation_angle_at_optimal", repr(spec.pennation))
        _sub(muscle, "max_contraction_velocity", "10")
        _sub(muscle, "ignore_tendon_compliance", "true")
    groups = _sub(force_set, "groups")
    for muscle_name, spec in MUSCLES.items():
        _sub(_sub(groups, "ObjectGroup", name=spec.channel), "members", muscle_name)
    _sub(_sub(groups, "ObjectGroup", name=SYNERGY_GROUP), "members", " ".join(MUSCLES))
    markers = _sub(_sub(model, "MarkerSet", name="markerset"), "objects")
    for marker_name, (body, location) in MARKERS.items():
        marker = _sub(markers, "Marker", name=marker_name)
        _sub(marker, "socket_parent_frame", f"/bodyset/{body}")
        _sub(marker, "location", _vec(location))
        _sub(marker, "fixed", "false")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")

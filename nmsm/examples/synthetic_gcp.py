"""A known-answer Ground Contact Personalization case, generated in code.

:func:`write_synthetic_gcp` writes into a folder:

* ``foot.osim``: a two-segment foot (``calcn`` moved by a 6-coordinate CustomJoint to
  ground whose rotation axes are Y, X, Z, so its coordinates are exactly GCP's foot
  coordinates; ``toes`` on a PinJoint ``mtp``) with the five GCP foot markers;
* ``ik.sto``: a treadmill stance (0.6 s, 100 Hz): the foot pitches from heel strike
  (toes up) through flat foot to heel rise with the toes staying flat, moving backwards
  with the belt, with small out-of-plane rotations; its height puts the lowest spring
  ``depth(t)`` below the resting spring length (up to 6 mm);
* ``grf.sto``: the ground reactions the contact model gives with the true springs and
  properties (:class:`SyntheticTruth`) for that motion, as a force plate reports them
  (moments about a fixed electrical center), so the experimental reactions GCP compares
  with are exactly the model's at the truth;
* ``settings.xml``: GCP settings (two tasks) starting from other values than the truth.

Running GCP on it must recover the ground reactions to numerical precision and the
properties closely (``tests/tools/gcp/test_synthetic.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np
from lxml import etree

from nmsm.io.storage import table_from_columns, write_storage

#: coordinates of the foot's joint to ground, in order (rotations about Y, X, Z; translations)
FOOT_JOINT_COORDINATES = ("foot_rotation_y", "foot_rotation_x", "foot_rotation_z", "foot_tx", "foot_ty", "foot_tz")
TOE_COORDINATE = "mtp_angle"
MARKERS = {  # name -> (body, location m)
    "Heel": ("calcn", (-0.03, 0.015, 0.0)),
    "Toe_Medial": ("calcn", (0.16, 0.0, -0.045)),
    "Toe_Lateral": ("calcn", (0.14, 0.0, 0.045)),
    "Midfoot_Superior": ("calcn", (0.10, 0.06, 0.0)),
    "Toe": ("toes", (0.065, 0.005, -0.01)),
}
#: toes joint location in the calcn frame (m)
MTP_LOCATION = (0.17, -0.015, 0.0)
#: calcn origin height (m) in the default pose: springs sit this far below it
DEFAULT_HEIGHT = 0.04
ELECTRICAL_CENTER = (0.4, 0.0, 0.25)
GRF_COLUMNS = {"force": ("f_vx", "f_vy", "f_vz"), "moment": ("m_x", "m_y", "m_z"), "center": ("f_px", "f_py", "f_pz")}


@attrs.frozen
class SyntheticTruth:
    """True contact properties; spring constants vary linearly from heel to toe."""

    heel_stiffness: float = 4000.0  #: N/m at the heel end of the grid
    toe_stiffness: float = 2500.0  #: N/m at the toe end
    damping_factor: float = 0.6  #: s/m
    dynamic_friction_coefficient: float = 0.7
    viscous_friction_coefficient: float = 0.1  #: s/m
    resting_spring_length: float = 0.004  #: m
    latching_velocity: float = 0.05  #: m/s
    belt_speed: float = 1.2  #: m/s

    def spring_constants(self, along: np.ndarray) -> np.ndarray:
        """Stiffness (N/m) of springs at normalized heel-to-toe positions ``along`` (0..1)."""
        return self.heel_stiffness + (self.toe_stiffness - self.heel_stiffness) * np.asarray(along, dtype=float)


@attrs.frozen
class SyntheticGcp:
    """Paths of the written case and its truth (``spring_constants`` (n,) N/m in the order of
    the springs nmsm places)."""

    folder: Path
    model_file: Path
    motion_file: Path
    grf_file: Path
    settings_file: Path
    truth: SyntheticTruth
    spring_constants: np.ndarray


# ------------------------------------------------------------------------------ model file
def _sub(parent: etree._Element, tag: str, text: str | None = None, **attributes: str) -> etree._Element:
    element = etree.SubElement(parent, tag, **attributes)
    if text is not None:
        element.text = text
    return element


def _vec(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _body(bodies: etree._Element, name: str, mass: float) -> None:
    body = _sub(bodies, "Body", name=name)
    _sub(body, "mass", repr(mass))
    _sub(body, "mass_center", "0 0 0")
    _sub(body, "inertia", "0.001 0.001 0.001 0 0 0")


def _coordinate(parent: etree._Element, name: str, default: float, rng: tuple[float, float]) -> None:
    c = _sub(parent, "Coordinate", name=name)
    _sub(c, "default_value", repr(default))
    _sub(c, "range", _vec(rng))
    _sub(c, "clamped", "false")
    _sub(c, "locked", "false")


def _frames(joint: etree._Element, parent: str, child: str, translation: Sequence[float]) -> None:
    _sub(joint, "socket_parent_frame", f"{parent}_offset")
    _sub(joint, "socket_child_frame", f"{child}_offset")
    frames = _sub(joint, "frames")
    for name, path, t in ((parent, "/ground" if parent == "ground" else f"/bodyset/{parent}", translation),
                          (child, f"/bodyset/{child}", (0, 0, 0))):
        frame = _sub(frames, "PhysicalOffsetFrame", name=f"{name}_offset")
        _sub(frame, "socket_parent", path)
        _sub(frame, "translation", _vec(t))
        _sub(frame, "orientation", "0 0 0")


def foot_model_xml() -> str:
    """The ``.osim`` text of the synthetic foot (module docstring)."""
    root = etree.Element("OpenSimDocument", Version="40000")
    model = _sub(root, "Model", name="synthetic_foot")
    _sub(model, "gravity", "0 -9.80665 0")
    _sub(model, "Ground", name="ground")
    bodies = _sub(_sub(model, "BodySet", name="bodyset"), "objects")
    _body(bodies, "calcn", 1.0)
    _body(bodies, "toes", 0.2)
    joints = _sub(_sub(model, "JointSet", name="jointset"), "objects")
    joint = _sub(joints, "CustomJoint", name="ground_calcn")
    coordinates = _sub(joint, "coordinates")
    for name in FOOT_JOINT_COORDINATES:
        default = DEFAULT_HEIGHT if name == "foot_ty" else 0.0
        _coordinate(coordinates, name, default, (-3.0, 3.0))
    _frames(joint, "ground", "calcn", (0, 0, 0))
    transform = _sub(joint, "SpatialTransform")
    axes = ((0, 1, 0), (1, 0, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1))
    for k, (name, axis) in enumerate(zip(FOOT_JOINT_COORDINATES, axes)):
        kind = "rotation" if k < 3 else "translation"
        ta = _sub(transform, "TransformAxis", name=f"{kind}{k % 3 + 1}")
        _sub(ta, "coordinates", name)
        _sub(ta, "axis", _vec(axis))
        function = _sub(ta, "LinearFunction", name="function")
        _sub(function, "coefficients", "1 0")
    pin = _sub(joints, "PinJoint", name="mtp")
    _coordinate(_sub(pin, "coordinates"), TOE_COORDINATE, 0.0, (-1.5, 1.5))
    _frames(pin, "calcn", "toes", MTP_LOCATION)
    markers = _sub(_sub(model, "MarkerSet", name="markerset"), "objects")
    for name, (body, location) in MARKERS.items():
        marker = _sub(markers, "Marker", name=name)
        _sub(marker, "socket_parent_frame", f"/bodyset/{body}")
        _sub(marker, "location", _vec(location))
        _sub(marker, "fixed", "false")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8").decode()


# ------------------------------------------------------------------------------ motion
def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (10 - 15 * x + 6 * x * x)


def stance_angles(time: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(pitch about z, rotation about y, rotation about x, toe angle)`` (rad) over ``time``."""
    s = (time - time[0]) / (time[-1] - time[0])
    pitch = 0.25 * (1 - _smoothstep(s / 0.3)) - 0.45 * _smoothstep((s - 0.6) / 0.4)
    toe = -np.minimum(pitch, 0.0)
    about_y = 0.05 * np.sin(2 * np.pi * s)
    about_x = 0.03 * np.sin(np.pi * s)
    return pitch, about_y, about_x, toe


def penetration(time: np.ndarray) -> np.ndarray:
    """Depth (m) of the lowest spring below the resting length: 0 at both ends, 6 mm mid."""
    s = (time - time[0]) / (time[-1] - time[0])
    return 0.006 * np.sin(np.pi * s) ** 1.5 + 0.001


# ------------------------------------------------------------------------------ the case
def write_synthetic_gcp(folder: str | Path, truth: SyntheticTruth = SyntheticTruth(), *, frames: int = 61,
                        grid: tuple[int, int] = (5, 7)) -> SyntheticGcp:
    """Write the synthetic case into ``folder`` (created) and return its paths and truth."""
    from nmsm.io.settings.document import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.run import load_feet
    from nmsm.tools.gcp.state import GcpState
    from nmsm.tools.gcp.values import as_array, foot_values

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    model_file = folder / "foot.osim"
    model_file.write_text(foot_model_xml(), encoding="utf-8")
    time = np.linspace(0.0, 0.6, frames)
    motion_file, grf_file, settings_file = folder / "ik.sto", folder / "grf.sto", folder / "settings.xml"
    settings_file.write_text(settings_xml(grid, truth), encoding="utf-8")
    pitch, about_y, about_x, toe = stance_angles(time)
    tx = 0.35 - truth.belt_speed * time
    tz = 0.25 + 0.01 * np.sin(np.pi * (time - time[0]) / (time[-1] - time[0]))
    values = {"foot_rotation_y": about_y, "foot_rotation_x": about_x, "foot_rotation_z": pitch, "foot_tx": tx,
              "foot_ty": np.full_like(time, DEFAULT_HEIGHT), "foot_tz": tz, TOE_COORDINATE: toe}
    write_storage(motion_file, table_from_columns(time, values, name="ik"))
    _write_grf(grf_file, time, np.zeros((frames, 3)), np.zeros((frames, 3)))
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(settings_file))
    feet, *_ = load_feet(settings)
    foot = feet[0]
    lowest = _lowest_spring_height(foot)
    values["foot_ty"] = DEFAULT_HEIGHT - lowest + truth.resting_spring_length - penetration(time)
    write_storage(motion_file, table_from_columns(time, values, name="ik"))
    feet, *_ = load_feet(settings)
    foot = feet[0]
    along = _normalized_along(foot)
    k_true = truth.spring_constants(along)
    state = GcpState.initial(settings, feet)
    state.spring_constants = k_true
    state.damping_factor = truth.damping_factor
    state.dynamic_friction_coefficient = truth.dynamic_friction_coefficient
    state.viscous_friction_coefficient = truth.viscous_friction_coefficient
    state.resting_spring_length = truth.resting_spring_length
    state.latching_velocity = truth.latching_velocity
    modeled = foot_values(foot, state.design(), 0)
    forces = as_array(modeled.forces).T
    moments = as_array(modeled.moments).T
    center = np.tile(np.asarray(ELECTRICAL_CENTER, dtype=float), (frames, 1))
    point = foot.midfoot.copy()
    point[:, 1] = 0.0
    lever = np.array([0.0, -truth.resting_spring_length, 0.0])
    plate_moments = moments - np.cross(center - point, forces) - np.cross(np.broadcast_to(lever, forces.shape), forces)
    _write_grf(grf_file, time, forces, plate_moments)
    return SyntheticGcp(folder, model_file, motion_file, grf_file, settings_file, truth, k_true)


def _write_grf(path: Path, time: np.ndarray, forces: np.ndarray, moments: np.ndarray) -> None:
    columns: dict[str, np.ndarray] = {}
    for k, label in enumerate(GRF_COLUMNS["force"]):
        columns[label] = forces[:, k]
    for k, label in enumerate(GRF_COLUMNS["center"]):
        columns[label] = np.full(time.size, ELECTRICAL_CENTER[k])
    for k, label in enumerate(GRF_COLUMNS["moment"]):
        columns[label] = moments[:, k]
    write_storage(path, table_from_columns(time, columns, name="grf"))


def _lowest_spring_height(foot: object) -> np.ndarray:
    """Lowest spring height (m) per frame at the experimental kinematics."""
    import casadi as cs

    positions = foot.foot.point_positions(foot.springs.points())
    function = cs.Function("springs", [foot.foot.q], [positions[1, :]])
    return np.array([float(np.min(np.array(function(q)))) for q in foot.coordinates])


def _normalized_along(foot: object) -> np.ndarray:
    """Heel-to-toe position (0..1) of each spring in the hindfoot frame (toes at 0)."""
    points = foot.foot.points_in_hindfoot(foot.springs.points())
    x = points[:, 0]
    return (x - x.min()) / (x.max() - x.min())


def settings_xml(grid: tuple[int, int], truth: SyntheticTruth = SyntheticTruth()) -> str:
    """GCP settings for the case: two tasks (all properties with kinematics, then again with
    moments weighted more), initial values away from the truth."""
    terms = """
        <RCNLCostTermSet>
          <RCNLCostTerm><is_enabled>true</is_enabled><type>marker_position</type><max_allowable_error>0.002</max_allowable_error></RCNLCostTerm>
          <RCNLCostTerm><is_enabled>true</is_enabled><type>rotation</type><max_allowable_error>0.01</max_allowable_error></RCNLCostTerm>
          <RCNLCostTerm><is_enabled>true</is_enabled><type>vertical_grf</type><max_allowable_error>{v}</max_allowable_error></RCNLCostTerm>
          <RCNLCostTerm><is_enabled>true</is_enabled><type>horizontal_grf</type><max_allowable_error>{h}</max_allowable_error></RCNLCostTerm>
          <RCNLCostTerm><is_enabled>true</is_enabled><type>ground_reaction_moment</type><max_allowable_error>{m}</max_allowable_error></RCNLCostTerm>
        </RCNLCostTermSet>"""
    flags = """<springConstants>true</springConstants><dampingFactor>true</dampingFactor>
        <dynamicFrictionCoefficient>true</dynamicFrictionCoefficient><viscousFrictionCoefficient>true</viscousFrictionCoefficient>
        <restingSpringLength>{rest}</restingSpringLength><kinematicsBSplineCoefficients>true</kinematicsBSplineCoefficients>"""
    tasks = "".join(
        f"<GCPTask><is_enabled>true</is_enabled><index>{i}</index>{flags.format(rest=rest)}"
        f"{terms.format(v=v, h=h, m=m)}</GCPTask>"
        for i, rest, v, h, m in ((1, "true", 5, 5, 2), (2, "false", 1, 1, 0.2)))
    return f"""<NMSMPipelineDocument Version="1.5.0">
  <GroundContactPersonalizationTool>
    <results_directory>results</results_directory>
    <input_model_file>foot.osim</input_model_file>
    <input_motion_file>ik.sto</input_motion_file>
    <input_grf_file>grf.sto</input_grf_file>
    <kinematics_filter_cutoff>10</kinematics_filter_cutoff>
    <initialize_resting_spring_length>true</initialize_resting_spring_length>
    <grid_width>{grid[0]}</grid_width>
    <grid_height>{grid[1]}</grid_height>
    <GCPContactSurfaceSet>
      <GCPContactSurface name="foot">
        <is_enabled>true</is_enabled><is_left_foot>false</is_left_foot>
        <start_time>0</start_time><end_time>0.6</end_time><belt_speed>{truth.belt_speed}</belt_speed>
        <force_columns>{" ".join(GRF_COLUMNS["force"])}</force_columns>
        <moment_columns>{" ".join(GRF_COLUMNS["moment"])}</moment_columns>
        <electrical_center_columns>{" ".join(GRF_COLUMNS["center"])}</electrical_center_columns>
        <hindfoot_body>calcn</hindfoot_body>
        <toe_marker>Toe</toe_marker><medial_marker>Toe_Medial</medial_marker><lateral_marker>Toe_Lateral</lateral_marker>
        <heel_marker>Heel</heel_marker><midfoot_superior_marker>Midfoot_Superior</midfoot_superior_marker>
      </GCPContactSurface>
    </GCPContactSurfaceSet>
    <GCPTaskList>{tasks}</GCPTaskList>
    <initial_resting_spring_length>0.02</initial_resting_spring_length>
    <initial_spring_constant>3000</initial_spring_constant>
    <initial_damping_factor>0.2</initial_damping_factor>
    <initial_dynamic_friction_coefficient>0.4</initial_dynamic_friction_coefficient>
    <initial_viscous_friction_coefficient>0.3</initial_viscous_friction_coefficient>
    <latching_velocity>{truth.latching_velocity}</latching_velocity>
    <function_tolerance>1e-12</function_tolerance>
    <step_tolerance>1e-12</step_tolerance>
    <optimality_tolerance>1e-10</optimality_tolerance>
    <max_iterations>60</max_iterations>
  </GroundContactPersonalizationTool>
</NMSMPipelineDocument>
"""

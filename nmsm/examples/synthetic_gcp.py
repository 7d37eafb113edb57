"""A known-answer Ground Contact Personalization case, generated in code.

:func:`write_synthetic_gcp` writes into a folder:

* ``foot.osim``: one or two two-segment feet (``calcn_<s>`` moved by a 6-coordinate
  CustomJoint to ground whose rotation axes are Y, X, Z for the right foot and -Y, -X, Z
  for the left, so its coordinates are exactly GCP's foot coordinates; ``toes_<s>`` on a
  PinJoint ``mtp_<s>``) with the five GCP foot markers (``R_``/``L_`` prefixes);
* ``ik.sto``: a treadmill stance per foot (0.6 s at 100 Hz; the left foot's window
  starts 0.5 s later): the foot pitches from heel strike (toes up) through flat foot to
  heel rise with the toes staying flat, moving backwards with the belt, with small
  out-of-plane rotations; its height puts the lowest spring ``depth(t)`` below the
  resting spring length (up to 7 mm). The left foot is the mirror image of the right;
* ``grf.sto``: per foot (plates ``1`` right, ``2`` left) the ground reactions the contact
  model gives with the true springs and properties (:class:`SyntheticTruth`) for that
  motion, as a force plate reports them (moments about a fixed electrical center), so the
  experimental reactions GCP compares with are exactly the model's at the truth;
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

#: coordinates of a foot's joint to ground, in order (rotations about Y, X, Z; translations)
FOOT_JOINT_COORDINATES = ("foot_rotation_y", "foot_rotation_x", "foot_rotation_z", "foot_tx", "foot_ty", "foot_tz")
TOE_COORDINATE = "mtp_angle"
#: marker -> (body, location m) of the right foot; the left foot mirrors z
MARKERS = {
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
#: side -> (marker prefix, plate, electrical center m, start of the stance s, z offset m)
SIDES = {
    "r": ("R_", "1", (0.4, 0.0, 0.25), 0.0, 0.25),
    "l": ("L_", "2", (0.4, 0.0, -0.25), 0.5, -0.25),
}
STANCE = 0.6  #: s
RATE = 100.0  #: Hz


def grf_columns(side: str) -> dict[str, tuple[str, str, str]]:
    """Force, moment and electrical-center column names of a side's plate."""
    plate = SIDES[side][1]
    return {"force": (f"f{plate}_vx", f"f{plate}_vy", f"f{plate}_vz"),
            "moment": (f"m{plate}_x", f"m{plate}_y", f"m{plate}_z"),
            "center": (f"f{plate}_px", f"f{plate}_py", f"f{plate}_pz")}


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


def foot_model_xml(sides: Sequence[str] = ("r",)) -> str:
    """The ``.osim`` text of the synthetic feet (module docstring)."""
    root = etree.Element("OpenSimDocument", Version="40000")
    model = _sub(root, "Model", name="synthetic_feet")
    _sub(model, "gravity", "0 -9.80665 0")
    _sub(model, "Ground", name="ground")
    bodies = _sub(_sub(model, "BodySet", name="bodyset"), "objects")
    joints = _sub(_sub(model, "JointSet", name="jointset"), "objects")
    markers = _sub(_sub(model, "MarkerSet", name="markerset"), "objects")
    for side in sides:
        mirror = -1.0 if side == "l" else 1.0
        _body(bodies, f"calcn_{side}", 1.0)
        _body(bodies, f"toes_{side}", 0.2)
        joint = _sub(joints, "CustomJoint", name=f"ground_calcn_{side}")
        coordinates = _sub(joint, "coordinates")
        for name in FOOT_JOINT_COORDINATES:
            default = DEFAULT_HEIGHT if name == "foot_ty" else 0.0
            _coordinate(coordinates, f"{name}_{side}", default, (-3.0, 3.0))
        _frames(joint, "ground", f"calcn_{side}", (0, 0, 0))
        transform = _sub(joint, "SpatialTransform")
        axes = ((0, mirror, 0), (mirror, 0, 0), (0, 0, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1))
        for k, (name, axis) in enumerate(zip(FOOT_JOINT_COORDINATES, axes)):
            kind = "rotation" if k < 3 else "translation"
            ta = _sub(transform, "TransformAxis", name=f"{kind}{k % 3 + 1}")
            _sub(ta, "coordinates", f"{name}_{side}")
            _sub(ta, "axis", _vec(axis))
            function = _sub(ta, "LinearFunction", name="function")
            _sub(function, "coefficients", "1 0")
        pin = _sub(joints, "PinJoint", name=f"mtp_{side}")
        _coordinate(_sub(pin, "coordinates"), f"{TOE_COORDINATE}_{side}", 0.0, (-1.5, 1.5))
        _frames(pin, f"calcn_{side}", f"toes_{side}", MTP_LOCATION)
        for name, (body, location) in MARKERS.items():
            marker = _sub(markers, "Marker", name=f"{SIDES[side][0]}{name}")
            _sub(marker, "socket_parent_frame", f"/bodyset/{body}_{side}")
            _sub(marker, "location", _vec((location[0], location[1], mirror * location[2])))
            _sub(marker, "fixed", "false")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8").decode()


# ------------------------------------------------------------------------------ motion
def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (10 - 15 * x + 6 * x * x)


def stance_angles(time: np.ndarray, start: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(pitch about z, rotation about y, rotation about x, toe angle)`` (rad) of a stance
    starting at ``start`` s, over ``time`` (inside the stance)."""
    s = (time - start) / STANCE
    pitch = 0.25 * (1 - _smoothstep(s / 0.3)) - 0.45 * _smoothstep((s - 0.6) / 0.4)
    toe = -np.minimum(pitch, 0.0)
    about_y = 0.05 * np.sin(2 * np.pi * s)
    about_x = 0.03 * np.sin(np.pi * s)
    return pitch, about_y, about_x, toe


def penetration(time: np.ndarray) -> np.ndarray:
    """Depth (m) of the lowest spring below the resting length over a stance's frames
    ``time``: 1 mm at both ends, 7 mm mid-stance."""
    s = (time - time[0]) / (time[-1] - time[0])
    return 0.006 * np.sin(np.pi * s) ** 1.5 + 0.001


# ------------------------------------------------------------------------------ the case
def _foot_motion(time: np.ndarray, start: float, side: str, belt_speed: float) -> dict[str, np.ndarray]:
    """Coordinates of one foot over the whole ``time`` (its stance from ``start``; clamped
    outside). Mirrored joint axes make the left foot the mirror image with equal values."""
    local = np.clip(time, start, start + STANCE)
    pitch, about_y, about_x, toe = stance_angles(local, start)
    z0 = SIDES[side][4]
    s = (local - start) / STANCE
    values = {"foot_rotation_y": about_y, "foot_rotation_x": about_x, "foot_rotation_z": pitch,
              "foot_tx": 0.35 - belt_speed * (local - start), "foot_ty": np.full_like(time, DEFAULT_HEIGHT),
              "foot_tz": z0 + np.sign(z0) * 0.01 * np.sin(np.pi * s), TOE_COORDINATE: toe}
    return {f"{k}_{side}": v for k, v in values.items()}


def write_synthetic_gcp(folder: str | Path, truth: SyntheticTruth = SyntheticTruth(), *,
                        sides: Sequence[str] = ("r",), grid: tuple[int, int] = (5, 7)) -> SyntheticGcp:
    """Write the synthetic case into ``folder`` (created) and return its paths and truth."""
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.run import load_feet
    from nmsm.tools.gcp.state import GcpState
    from nmsm.tools.gcp.values import as_array, foot_values

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    sides = tuple(sides)
    model_file = folder / "foot.osim"
    model_file.write_text(foot_model_xml(sides), encoding="utf-8")
    end = max(SIDES[side][3] for side in sides) + STANCE
    time = np.round(np.arange(0.0, end + 0.5 / RATE, 1.0 / RATE), 10)
    motion_file, grf_file, settings_file = folder / "ik.sto", folder / "grf.sto", folder / "settings.xml"
    settings_file.write_text(settings_xml(grid, truth, sides), encoding="utf-8")
    values: dict[str, np.ndarray] = {}
    for side in sides:
        values.update(_foot_motion(time, SIDES[side][3], side, truth.belt_speed))
    write_storage(motion_file, table_from_columns(time, values, name="ik"))
    plates = {side: (np.zeros((time.size, 3)), np.zeros((time.size, 3))) for side in sides}
    _write_grf(grf_file, time, plates)
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(settings_file))
    feet, *_ = load_feet(settings)
    for side, foot in zip(sides, feet):
        rows = np.flatnonzero(np.isin(np.round(time, 9), np.round(foot.time, 9)))
        ty = values[f"foot_ty_{side}"]
        ty[rows] = DEFAULT_HEIGHT - _lowest_spring_height(foot) + truth.resting_spring_length - penetration(foot.time)
        ty[: rows[0]] = ty[rows[0]]
        ty[rows[-1] + 1:] = ty[rows[-1]]
    write_storage(motion_file, table_from_columns(time, values, name="ik"))
    feet, *_ = load_feet(settings)
    k_true = truth.spring_constants(_normalized_along(feet[0]))
    state = GcpState.initial(settings, feet)
    state.spring_constants = k_true
    state.damping_factor = truth.damping_factor
    state.dynamic_friction_coefficient = truth.dynamic_friction_coefficient
    state.viscous_friction_coefficient = truth.viscous_friction_coefficient
    state.resting_spring_length = truth.resting_spring_length
    state.latching_velocity = truth.latching_velocity
    design = state.design()
    for i, (side, foot) in enumerate(zip(sides, feet)):
        modeled = foot_values(foot, design, i)
        forces = as_array(modeled.forces).T
        moments = as_array(modeled.moments).T
        center = np.tile(np.asarray(SIDES[side][2], dtype=float), (foot.n_frames, 1))
        point = foot.midfoot.copy()
        point[:, 1] = 0.0
        lever = np.broadcast_to(np.array([0.0, -truth.resting_spring_length, 0.0]), forces.shape)
        rows = np.flatnonzero(np.isin(np.round(time, 9), np.round(foot.time, 9)))
        plates[side][0][rows] = forces
        plates[side][1][rows] = moments - np.cross(center - point, forces) - np.cross(lever, forces)
    _write_grf(grf_file, time, plates)
    return SyntheticGcp(folder, model_file, motion_file, grf_file, settings_file, truth, k_true)


def _write_grf(path: Path, time: np.ndarray, plates: dict[str, tuple[np.ndarray, np.ndarray]]) -> None:
    columns: dict[str, np.ndarray] = {}
    for side, (forces, moments) in plates.items():
        names = grf_columns(side)
        for k in range(3):
            columns[names["force"][k]] = forces[:, k]
            columns[names["center"][k]] = np.full(time.size, SIDES[side][2][k])
            columns[names["moment"][k]] = moments[:, k]
    write_storage(path, table_from_columns(time, columns, name="grf"))


def _lowest_spring_height(foot: object) -> np.ndarray:
    """Lowest spring height (m) per frame of the foot's window at the experimental kinematics."""
    import casadi as cs

    positions = foot.foot.point_positions(foot.springs.points())
    function = cs.Function("springs", [foot.foot.q], [positions[1, :]])
    return np.array([float(np.min(np.array(function(q)))) for q in foot.coordinates])


def _normalized_along(foot: object) -> np.ndarray:
    """Heel-to-toe position (0..1) of each spring in the hindfoot frame (toes at 0)."""
    points = foot.foot.points_in_hindfoot(foot.springs.points())
    x = points[:, 0]
    return (x - x.min()) / (x.max() - x.min())


def settings_xml(grid: tuple[int, int], truth: SyntheticTruth = SyntheticTruth(), sides: Sequence[str] = ("r",)) -> str:
    """GCP settings for the case: two tasks (all properties with kinematics, then again with
    forces and moments weighted more), initial values away from the truth."""
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
    surfaces = ""
    for side in sides:
        prefix, _, _, start, _ = SIDES[side]
        names = grf_columns(side)
        surfaces += f"""
      <GCPContactSurface name="{side}">
        <is_enabled>true</is_enabled><is_left_foot>{"true" if side == "l" else "false"}</is_left_foot>
        <start_time>{start}</start_time><end_time>{start + STANCE}</end_time><belt_speed>{truth.belt_speed}</belt_speed>
        <force_columns>{" ".join(names["force"])}</force_columns>
        <moment_columns>{" ".join(names["moment"])}</moment_columns>
        <electrical_center_columns>{" ".join(names["center"])}</electrical_center_columns>
        <hindfoot_body>calcn_{side}</hindfoot_body>
        <toe_marker>{prefix}Toe</toe_marker><medial_marker>{prefix}Toe_Medial</medial_marker>
        <lateral_marker>{prefix}Toe_Lateral</lateral_marker><heel_marker>{prefix}Heel</heel_marker>
        <midfoot_superior_marker>{prefix}Midfoot_Superior</midfoot_superior_marker>
      </GCPContactSurface>"""
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
    <GCPContactSurfaceSet>{surfaces}
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

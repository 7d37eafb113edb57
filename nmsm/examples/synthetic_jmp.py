"""A known-answer Joint Model Personalization case generated in code.

:func:`make_synthetic_jmp_case` writes into a folder:

* ``true.osim``: the model that made the markers: a leg built here (:func:`leg_model_xml`:
  pelvis with 6 coordinates, ball-like hip, pin knee, pin ankle, 12 markers), or a given
  model (e.g. the RCNL full-body model, right side);
* ``nominal.osim``: the same model with the knee's parent and child frame orientations
  and the ankle's parent frame orientation (x and y, the axes JMP estimates) perturbed;
* ``markers.trc`` (mm): markers of the true model over a smooth motion exercising every
  free coordinate within its range, plus Gaussian noise of ``noise`` m per component;
* ``JMPSettings.xml``: one task personalizing those parameters of ``nominal.osim``.

JMP run on the settings should recover the true parameters (``case.truth``, by design
variable label). :func:`run_example` does it and returns the recovery errors; the leg
model needs nothing outside nmsm (``nmsm example`` can use it).

Units: m, rad; marker file in mm.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np
from lxml import etree

#: perturbation pattern (multiples of ``perturbation``) of (knee parent x, y, knee child x, y, ankle parent x, y)
_PATTERN = (1.0, -0.8, -0.6, 0.9, 0.7, -1.0)
SETTINGS_FILE = "JMPSettings.xml"


@attrs.frozen
class SyntheticJmpCase:
    """Files of a synthetic case and the true values of its design variables (label -> rad)."""

    folder: Path
    settings_file: Path
    true_model: Path
    nominal_model: Path
    marker_file: Path
    truth: dict[str, float]
    noise: float
    knee: str
    ankle: str


# ------------------------------------------------------------------------------ the leg model
def _sub(parent: etree._Element, tag: str, text: str | None = None, **attributes: str) -> etree._Element:
    elem = etree.SubElement(parent, tag, **attributes)
    if text is not None:
        elem.text = text
    return elem


def _vec(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _coordinate(parent: etree._Element, name: str, default: float, lower: float, upper: float,
                clamped: bool = False) -> None:
    c = _sub(parent, "Coordinate", name=name)
    _sub(c, "default_value", repr(float(default)))
    _sub(c, "default_speed_value", "0")
    _sub(c, "range", _vec((lower, upper)))
    _sub(c, "clamped", "true" if clamped else "false")
    _sub(c, "locked", "false")


def _offset(parent: etree._Element, name: str, body_path: str, translation: Sequence[float],
            orientation: Sequence[float] = (0, 0, 0)) -> None:
    frame = _sub(parent, "PhysicalOffsetFrame", name=name)
    _sub(frame, "socket_parent", body_path)
    _sub(frame, "translation", _vec(translation))
    _sub(frame, "orientation", _vec(orientation))


def _axis(transform: etree._Element, name: str, coordinate: str | None, axis: Sequence[float]) -> None:
    ta = _sub(transform, "TransformAxis", name=name)
    _sub(ta, "coordinates", coordinate or "")
    _sub(ta, "axis", _vec(axis))
    if coordinate:
        f = _sub(ta, "LinearFunction", name="function")
        _sub(f, "coefficients", "1 0")
    else:
        f = _sub(ta, "Constant", name="function")
        _sub(f, "value", "0")


def _custom_joint(joints: etree._Element, name: str, parent: str, child: str, parent_translation: Sequence[float],
                  rotations: Sequence[tuple[str, Sequence[float], float, float]],
                  translations: Sequence[tuple[str, Sequence[float], float, float, float]] = ()) -> None:
    joint = _sub(joints, "CustomJoint", name=name)
    _sub(joint, "socket_parent_frame", f"{parent}_offset")
    _sub(joint, "socket_child_frame", f"{child}_offset")
    coords = _sub(joint, "coordinates")
    for cname, _, lower, upper in rotations:
        _coordinate(coords, cname, 0.0, lower, upper)
    for cname, _, default, lower, upper in translations:
        _coordinate(coords, cname, default, lower, upper)
    frames = _sub(joint, "frames")
    _offset(frames, f"{parent}_offset", "/ground" if parent == "ground" else f"/bodyset/{parent}", parent_translation)
    _offset(frames, f"{child}_offset", f"/bodyset/{child}", (0, 0, 0))
    transform = _sub(joint, "SpatialTransform")
    for k, (cname, axis, _, _) in enumerate(rotations, start=1):
        _axis(transform, f"rotation{k}", cname, axis)
    units = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    named = {tuple(axis): cname for cname, axis, *_ in translations}
    for k, unit in enumerate(units, start=1):
        _axis(transform, f"translation{k}", named.get(unit), unit)


def _pin_joint(joints: etree._Element, name: str, coordinate: str, parent: str, child: str,
               parent_translation: Sequence[float], lower: float, upper: float) -> None:
    joint = _sub(joints, "PinJoint", name=name)
    _sub(joint, "socket_parent_frame", f"{parent}_offset")
    _sub(joint, "socket_child_frame", f"{child}_offset")
    coords = _sub(joint, "coordinates")
    _coordinate(coords, coordinate, 0.0, lower, upper, clamped=True)
    frames = _sub(joint, "frames")
    _offset(frames, f"{parent}_offset", f"/bodyset/{parent}", parent_translation)
    _offset(frames, f"{child}_offset", f"/bodyset/{child}", (0, 0, 0))


#: body -> (mass kg, centre of mass m, principal inertia kg m^2)
_BODIES = {
    "pelvis": (10.0, (-0.07, 0.0, 0.0), (0.09, 0.08, 0.05)),
    "thigh": (8.0, (0.0, -0.18, 0.0), (0.12, 0.03, 0.12)),
    "shank": (3.5, (0.0, -0.19, 0.0), (0.05, 0.005, 0.05)),
    "foot": (1.2, (0.08, -0.03, 0.0), (0.002, 0.005, 0.005)),
}
#: marker -> (body, location m)
_MARKERS = {
    "ASIS_R": ("pelvis", (0.02, 0.0, 0.12)),
    "ASIS_L": ("pelvis", (0.02, 0.0, -0.12)),
    "SACRUM": ("pelvis", (-0.15, 0.03, 0.0)),
    "THIGH_SUP": ("thigh", (0.05, -0.12, 0.04)),
    "THIGH_LAT": ("thigh", (0.0, -0.22, 0.07)),
    "THIGH_INF": ("thigh", (0.06, -0.30, 0.02)),
    "SHANK_SUP": ("shank", (0.04, -0.08, 0.03)),
    "SHANK_LAT": ("shank", (-0.02, -0.18, 0.06)),
    "SHANK_INF": ("shank", (0.03, -0.30, 0.02)),
    "HEEL": ("foot", (-0.04, -0.03, 0.0)),
    "MIDFOOT_LAT": ("foot", (0.09, -0.02, 0.04)),
    "TOE": ("foot", (0.18, -0.03, -0.01)),
}


def leg_model_xml() -> bytes:
    """An OpenSim 4 model of one leg (see module docstring), as file bytes."""
    root = etree.Element("OpenSimDocument", Version="40000")
    model = _sub(root, "Model", name="synthetic_leg")
    ground = _sub(model, "Ground", name="ground")
    ground.text = None
    _sub(model, "gravity", "0 -9.8066499999999994 0")
    bodies = _sub(_sub(model, "BodySet", name="bodyset"), "objects")
    for name, (mass, com, inertia) in _BODIES.items():
        body = _sub(bodies, "Body", name=name)
        _sub(body, "mass", repr(mass))
        _sub(body, "mass_center", _vec(com))
        _sub(body, "inertia", _vec((*inertia, 0, 0, 0)))
    joints = _sub(_sub(model, "JointSet", name="jointset"), "objects")
    half_pi = np.pi / 2
    _custom_joint(joints, "ground_pelvis", "ground", "pelvis", (0, 0, 0),
                  [("pelvis_tilt", (0, 0, 1), -half_pi, half_pi), ("pelvis_list", (1, 0, 0), -half_pi, half_pi),
                   ("pelvis_rotation", (0, 1, 0), -half_pi, half_pi)],
                  [("pelvis_tx", (1, 0, 0), 0.0, -5, 5), ("pelvis_ty", (0, 1, 0), 0.93, -1, 2),
                   ("pelvis_tz", (0, 0, 1), 0.0, -3, 3)])
    _custom_joint(joints, "hip", "pelvis", "thigh", (-0.06, -0.08, 0.085),
                  [("hip_flexion", (0, 0, 1), -0.5, 2.0), ("hip_adduction", (1, 0, 0), -0.8, 0.5),
                   ("hip_rotation", (0, 1, 0), -0.7, 0.7)])
    _pin_joint(joints, "knee", "knee_angle", "thigh", "shank", (-0.005, -0.40, 0.0), -2.1, 0.05)
    _pin_joint(joints, "ankle", "ankle_angle", "shank", "foot", (-0.01, -0.40, 0.0), -0.7, 0.5)
    markers = _sub(_sub(model, "MarkerSet", name="markerset"), "objects")
    for name, (body, location) in _MARKERS.items():
        marker = _sub(markers, "Marker", name=name)
        _sub(marker, "socket_parent_frame", f"/bodyset/{body}")
        _sub(marker, "location", _vec(location))
        _sub(marker, "fixed", "false")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


# ------------------------------------------------------------------------------ the case
def _motion(model, names: Sequence[str], time: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """Smooth motion ``(F, n)`` of the free coordinates ``names`` within their ranges
    (rotations up to +-0.6 rad, translations +-0.05 m, times ``scale``)."""
    out = np.zeros((time.size, len(names)))
    duration = time[-1] - time[0] if time.size > 1 else 1.0
    for k, name in enumerate(names):
        c = model.coordinate(name)
        lower, upper = c.range
        if c.motion_type == "rotational":
            lower, upper = max(lower, -np.pi / 2), min(upper, np.pi / 2)
            centre = 0.5 * (lower + upper)
            amplitude = min(0.35 * (upper - lower), 0.6)
        else:
            centre, amplitude = c.default_value, 0.05
        frequency = (1.0 + 0.37 * k) / duration
        out[:, k] = centre + scale * amplitude * np.sin(2 * np.pi * frequency * (time - time[0]) + 0.9 * k)
    return out


def _chain_markers(model, knee: str, ankle: str) -> list[str]:
    """Markers on the knee's and ankle's bodies, everything distal to the ankle, and the body
    proximal to the knee's parent (the pelvis)."""
    knee_joint, ankle_joint = model.joint(knee), model.joint(ankle)
    distal = {ankle_joint.child_body}
    for joint in model.joints:  # tree order: a parent is reached before its children
        if joint.parent_body in distal:
            distal.add(joint.child_body)
    bodies = distal | {knee_joint.parent_body, knee_joint.child_body, ankle_joint.parent_body}
    bodies |= {j.parent_body for j in model.joints if j.child_body == knee_joint.parent_body}
    return [m.name for m in model.markers if m.body in bodies]


def _settings_xml(model_name: str, markers: Sequence[str], knee: str, ankle: str) -> bytes:
    from nmsm.io.settings.document import PIPELINE_VERSION_TEXT

    root = etree.Element("NMSMPipelineDocument", Version=PIPELINE_VERSION_TEXT)
    tool = _sub(root, "JointModelPersonalizationTool", name="synthetic")
    _sub(tool, "results_directory", "results")
    _sub(tool, "input_model_file", model_name)
    _sub(tool, "output_model_file", "personalized.osim")
    _sub(tool, "allowable_error", "0.01")
    task = _sub(_sub(tool, "JMPTaskList"), "JMPTask", name="knee and ankle")
    _sub(task, "is_enabled", "true")
    _sub(task, "index", "1")
    _sub(task, "marker_file_name", "markers.trc")
    _sub(task, "marker_names", " ".join(markers))
    joints = _sub(task, "JMPJointSet")
    for name, parent, child in ((knee, "true true false", "true true false"),
                                (ankle, "true true false", "false false false")):
        joint = _sub(joints, "JMPJoint", name=name)
        for tag, flags in (("parent_frame_transformation", parent), ("child_frame_transformation", child)):
            frame = _sub(joint, tag)
            _sub(frame, "translation", "false false false")
            _sub(frame, "orientation", flags)
            _sub(frame, "translation_bounds", "0.05")
            _sub(frame, "orientation_bounds", "0.5")
    for tag, value in (("accuracy", "1e-8"), ("optimality_tolerance", "1e-10"), ("function_tolerance", "1e-12"),
                       ("step_tolerance", "1e-10"), ("max_function_evaluations", "500")):
        _sub(tool, tag, value)
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


def make_synthetic_jmp_case(folder: str | os.PathLike[str], *, model_file: str | os.PathLike[str] | None = None,
                            knee: str | None = None, ankle: str | None = None, perturbation: float = np.radians(5.0),
                            noise: float = 0.0005, duration: float = 2.0, rate: float = 100.0,
                            motion_scale: float = 1.0, seed: int = 0) -> SyntheticJmpCase:
    """Write a synthetic JMP case into ``folder`` (see module docstring).

    ``model_file``: the true model (default: the built-in leg, joints ``knee``/``ankle``);
    ``knee``/``ankle``: its joint names (default ``knee``/``ankle``, or ``knee_r``/``ankle_r``
    for a given model). ``perturbation`` (rad) scales the offsets of the nominal model;
    ``noise`` (m) is the standard deviation of the marker noise; ``duration`` (s) and
    ``rate`` (Hz) set the frames; ``motion_scale`` scales the range of motion (a small one
    makes joint parameters unidentifiable, which JMP warns about).
    """
    from nmsm.io.trc import MarkerTable, write_trc
    from nmsm.model.osim import load_model
    from nmsm.model.osim_writer import OsimWriter
    from nmsm.tools.jmp.marker_model import MarkerKinematics

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    true_model = folder / "true.osim"
    if model_file is None:
        true_model.write_bytes(leg_model_xml())
        knee, ankle = knee or "knee", ankle or "ankle"
    else:
        true_model.write_bytes(Path(model_file).read_bytes())
        knee, ankle = knee or "knee_r", ankle or "ankle_r"
    model = load_model(true_model)
    markers = _chain_markers(model, knee, ankle)
    kinematics = MarkerKinematics(model, markers)
    time = np.arange(int(round(duration * rate)) + 1) / rate
    q = _motion(model, kinematics.free_names, time, motion_scale)
    positions = kinematics.marker_positions(q)
    rng = np.random.default_rng(seed)
    positions = positions + rng.normal(scale=noise, size=positions.shape) if noise > 0 else positions
    marker_file = folder / "markers.trc"
    write_trc(marker_file, MarkerTable(time=time, names=tuple(markers), positions=positions, units="mm",
                                       data_rate=rate, camera_rate=rate), units="mm")
    writer = OsimWriter(true_model)
    truth: dict[str, float] = {}
    frames = [(knee, "parent", 0), (knee, "parent", 1), (knee, "child", 0), (knee, "child", 1),
              (ankle, "parent", 0), (ankle, "parent", 1)]
    nominal: dict[str, np.ndarray] = {}
    for (joint, which, axis), factor in zip(frames, _PATTERN):
        path = writer.joint_frame_path(joint, which)
        values = nominal.setdefault(path, model.frames[path].orientation.copy())
        truth[f"{joint} {which} orientation {'xyz'[axis]}"] = float(values[axis])
        values[axis] += factor * perturbation
    for path, values in nominal.items():
        writer.set_frame_orientation(path, values)
    nominal_model = writer.write(folder / "nominal.osim")
    settings_file = folder / SETTINGS_FILE
    settings_file.write_bytes(_settings_xml(nominal_model.name, markers, knee, ankle))
    return SyntheticJmpCase(folder=folder, settings_file=settings_file, true_model=true_model,
                            nominal_model=nominal_model, marker_file=marker_file, truth=truth, noise=noise,
                            knee=knee, ankle=ankle)


def recovery_errors(case: SyntheticJmpCase, run) -> dict[str, float]:
    """Recovered minus true value (rad) of each design variable of a finished run."""
    task = run.tasks[0]
    values = {v.label: float(x) for v, x in zip(task.design.variables, task.values)}
    return {label: values[label] - truth for label, truth in case.truth.items()}


def run_example(folder: str | os.PathLike[str], **options) -> tuple[SyntheticJmpCase, object, dict[str, float]]:
    """Make the built-in leg case in ``folder``, run JMP on it, return ``(case, run, errors)``
    (errors in rad, by design variable label). ``options`` go to :func:`make_synthetic_jmp_case`."""
    from nmsm.tools.jmp.run import run_settings

    case = make_synthetic_jmp_case(folder, **options)
    run = run_settings(case.settings_file, quiet=True)
    return case, run, recovery_errors(case, run)

"""A small muscle- and synergy-driven Treatment Optimization problem with foot contact, for
checking terms (:func:`nmsm.testing.check_term`) that the pendulum cannot serve.

Written in code into a temporary folder (removed at exit), once per process:

* ``leg.osim``: a planar leg hanging from a hip fixed to the ground at :data:`HIP_HEIGHT`
  (x forward, y up, z out of the plane), on the pendulum's names where they overlap: hip
  ``q0`` (thigh ``link_0``, marker ``tip_0`` at the knee), knee ``q1`` (shank ``link_1``,
  marker ``tip_1`` at the ankle), ankle ``q2`` (hindfoot ``calcn``), toes ``q3`` (``toes``);
  foot markers ``heel``, ``toe``, ``midfoot``; three path-point muscles
  (:data:`MUSCLES`) in the ForceSet group ``group``;
* ``leg.osimx``: the synergy group ``group`` with two synergies (``group_1``, ``group_2``)
  and an elastic-foundation contact surface on ``calcn`` (:data:`SPRINGS`; treadmill belt at
  0.2 m/s, slower than the foot's swing, so the forward force changes sign) whose
  ground-reaction columns are ``ground_force_v[xyz]``, ``ground_torque_[xyz]`` and
  ``ground_force_p[xyz]``;
* ``surrogate/``: the muscles' exact path geometry (:func:`nmsm.model.muscle_analysis.analyze_motion`)
  on a grid of knee and ankle poses, from which the synergy controller fits its surrogate.

The problem (:func:`build_leg_problem`): states ``q0``..``q3`` over 1 s, 3 mesh intervals of
3 collocation points, starting on the tracked motion (:func:`motion`); a torque control on
``q0`` (``q0_moment``) and the synergy controller on ``q1``, ``q2`` (its synergy vectors
optimized, except in VO; its surrogate of degree 3). The tracked data are the model's own on
the tracked motion, sampled on the mesh nodes, where their splines interpolate exactly: ground
reactions of the contact surface (torques about the midfoot marker's floor point, which stands
for the electrical centre, so the tracked centre of pressure is the model's), activations
``C W`` of the starting synergy commands ``C`` and vectors ``W``. A tracking term of these is
zero at the start.
"""

from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import casadi as cs
import numpy as np
from lxml import etree

#: duration of the movement (s)
DURATION = 1.0
#: height of the hip above the floor (m): the sole's springs are compressed a few mm
HIP_HEIGHT = 0.87
COORDINATES = ("q0", "q1", "q2", "q3")
STATES = COORDINATES
#: (name, parent, child, joint origin in the parent (m), coordinate)
JOINTS = (("hip", "ground", "link_0", (0.0, HIP_HEIGHT, 0.0), "q0"),
          ("knee", "link_0", "link_1", (0.0, -0.4, 0.0), "q1"),
          ("ankle", "link_1", "calcn", (0.0, -0.4, 0.0), "q2"),
          ("mtp", "calcn", "toes", (0.13, -0.05, 0.0), "q3"))
#: body -> (mass kg, centre of mass m)
BODIES = {"link_0": (7.0, (0.0, -0.18, 0.0)), "link_1": (3.0, (0.0, -0.18, 0.0)),
          "calcn": (1.0, (0.04, -0.03, 0.0)), "toes": (0.2, (0.02, -0.005, 0.0))}
MARKERS = {"tip_0": ("link_0", (0.0, -0.4, 0.0)), "tip_1": ("link_1", (0.0, -0.4, 0.0)),
           "heel": ("calcn", (-0.05, -0.03, 0.0)), "toe": ("toes", (0.05, -0.01, 0.0)),
           "midfoot": ("calcn", (0.06, 0.0, 0.0)), "medial": ("calcn", (0.1, -0.04, -0.04)),
           "lateral": ("calcn", (0.1, -0.04, 0.04))}
#: muscle -> (path points (body, location m), F0 N, l_o m, pennation rad)
MUSCLES = {"muscle_0": ((("link_0", (0.03, -0.2, 0.0)), ("link_1", (0.04, -0.05, 0.0))), 3000.0, 0.10, 0.05),
           "muscle_1": ((("link_0", (-0.02, -0.38, 0.0)), ("calcn", (-0.05, -0.02, 0.0))), 2500.0, 0.06, 0.2),
           "muscle_2": ((("link_1", (0.03, -0.15, 0.0)), ("calcn", (0.08, -0.03, 0.0))), 1200.0, 0.08, 0.1)}
GROUP = "group"
SYNERGIES = ("group_1", "group_2")
#: (S, M) starting synergy vectors
WEIGHTS = np.array([[0.6, 0.3, 0.1], [0.1, 0.3, 0.6]])
#: springs (body, location m, spring constant N/m)
SPRINGS = (("calcn", (-0.04, -0.06, -0.03), 20000.0), ("calcn", (-0.04, -0.06, 0.03), 20000.0),
           ("calcn", (0.07, -0.06, -0.03), 24000.0), ("calcn", (0.07, -0.06, 0.03), 24000.0),
           ("toes", (0.03, -0.01, -0.02), 16000.0), ("toes", (0.03, -0.01, 0.02), 16000.0))
CONTACT = {"damping_factor": 0.25, "dynamic_friction_coefficient": 0.7, "viscous_friction_coefficient": 0.3,
           "resting_spring_length": 0.012, "latching_velocity": 0.05, "belt_speed": 0.2}
GRF_COLUMNS = {"force": ("ground_force_vx", "ground_force_vy", "ground_force_vz"),
               "moment": ("ground_torque_x", "ground_torque_y", "ground_torque_z"),
               "center": ("ground_force_px", "ground_force_py", "ground_force_pz")}
TRIAL = "leg"


def motion(t: np.ndarray) -> np.ndarray:
    """(n, 4) tracked coordinates (rad) at times ``t`` (s): a slow swing with the foot on the belt."""
    w = 2 * np.pi * np.asarray(t, dtype=float)[:, None] / DURATION
    amplitude = np.array([0.06, 0.08, 0.07, 0.05])
    offset = np.array([0.0, -0.05, 0.0, 0.0])
    phase = np.array([0.0, 0.7, 1.4, 2.1])
    return offset + amplitude * np.sin(w + phase)


# ------------------------------------------------------------------------------ the files
def _sub(parent: etree._Element, tag: str, text: str | None = None, **attributes: str) -> etree._Element:
    element = etree.SubElement(parent, tag, **attributes)
    if text is not None:
        element.text = text
    return element


def _vec(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _planar_point(q: np.ndarray, body: str, location: Sequence[float]) -> np.ndarray:
    """(x, y) in ground of a point of ``body`` at pose ``q`` (4,) (rad): the planar chain."""
    path = []
    current = body
    while current != "ground":
        joint = next(j for j in JOINTS if j[2] == current)
        path.append(joint)
        current = joint[1]
    point = np.asarray(location[:2], dtype=float)
    for _, _, _, origin, coordinate in path:
        angle = q[COORDINATES.index(coordinate)]
        c, s = np.cos(angle), np.sin(angle)
        point = np.array([c * point[0] - s * point[1], s * point[0] + c * point[1]]) + np.asarray(origin[:2])
    return point


def _tendon_slack_lengths() -> dict[str, float]:
    """Tendon slack lengths (m) putting each muscle's fiber at its optimal length in the
    pose of the tracked motion's start."""
    q = motion(np.zeros(1))[0]
    out = {}
    for name, (points, _, optimal, pennation) in MUSCLES.items():
        ends = [_planar_point(q, body, location) for body, location in points]
        length = float(np.linalg.norm(ends[1] - ends[0]))
        out[name] = float(length - optimal * np.cos(pennation))
    return out


def leg_model_xml() -> bytes:
    """The OpenSim 4 model text of the module docstring."""
    root = etree.Element("OpenSimDocument", Version="40000")
    model = _sub(root, "Model", name="check_term_leg")
    _sub(model, "Ground", name="ground")
    _sub(model, "gravity", "0 -9.80665 0")
    bodies = _sub(_sub(model, "BodySet", name="bodyset"), "objects")
    for name, (mass, centre) in BODIES.items():
        body = _sub(bodies, "Body", name=name)
        _sub(body, "mass", repr(mass))
        _sub(body, "mass_center", _vec(centre))
        _sub(body, "inertia", _vec((0.02 * mass, 0.005 * mass, 0.02 * mass, 0, 0, 0)))
    joints = _sub(_sub(model, "JointSet", name="jointset"), "objects")
    for name, parent, child, origin, coordinate in JOINTS:
        joint = _sub(joints, "PinJoint", name=name)
        _sub(joint, "socket_parent_frame", f"{parent}_offset")
        _sub(joint, "socket_child_frame", f"{child}_offset")
        element = _sub(_sub(joint, "coordinates"), "Coordinate", name=coordinate)
        _sub(element, "default_value", "0")
        _sub(element, "range", "-1.5 1.5")
        frames = _sub(joint, "frames")
        for frame, body, offset in ((f"{parent}_offset", parent, origin), (f"{child}_offset", child, (0, 0, 0))):
            f = _sub(frames, "PhysicalOffsetFrame", name=frame)
            _sub(f, "socket_parent", "/ground" if body == "ground" else f"/bodyset/{body}")
            _sub(f, "translation", _vec(offset))
            _sub(f, "orientation", "0 0 0")
    markers = _sub(_sub(model, "MarkerSet", name="markerset"), "objects")
    for name, (body, location) in MARKERS.items():
        marker = _sub(markers, "Marker", name=name)
        _sub(marker, "socket_parent_frame", f"/bodyset/{body}")
        _sub(marker, "location", _vec(location))
    force_set = _sub(model, "ForceSet", name="forceset")
    forces = _sub(force_set, "objects")
    slack = _tendon_slack_lengths()
    for name, (points, force, optimal, pennation) in MUSCLES.items():
        muscle = _sub(forces, "Millard2012EquilibriumMuscle", name=name)
        _sub(muscle, "appliesForce", "true")
        path_points = _sub(_sub(_sub(muscle, "GeometryPath", name="path"), "PathPointSet"), "objects")
        for k, (body, location) in enumerate(points):
            point = _sub(path_points, "PathPoint", name=f"{name}-P{k + 1}")
            _sub(point, "socket_parent_frame", f"/bodyset/{body}")
            _sub(point, "location", _vec(location))
        _sub(muscle, "max_isometric_force", repr(force))
        _sub(muscle, "optimal_fiber_length", repr(optimal))
        _sub(muscle, "tendon_slack_length", repr(slack[name]))
        _sub(muscle, "pennation_angle_at_optimal", repr(pennation))
    group = _sub(_sub(force_set, "groups"), "ObjectGroup", name=GROUP)
    _sub(group, "members", " ".join(MUSCLES))
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


def _osimx() -> Any:
    from nmsm.io.osimx import GcpSpring, OsimxContactSurface, OsimxModel, OsimxSynergy

    springs = tuple(GcpSpring(f"spring_{k}", body, tuple(float(v) for v in location), k_)
                    for k, (body, location, k_) in enumerate(SPRINGS))
    surface = OsimxContactSurface(
        is_left_foot=False, force_columns=GRF_COLUMNS["force"], moment_columns=GRF_COLUMNS["moment"],
        electrical_center_columns=GRF_COLUMNS["center"], hindfoot_body="calcn", toe_marker="toe",
        medial_marker="medial", lateral_marker="lateral", heel_marker="heel", midfoot_superior_marker="midfoot",
        springs=springs, **CONTACT)
    return OsimxModel(name="check_term_leg", associated_osim_model="leg.osim", contact_surfaces=(surface,),
                      synergies=(OsimxSynergy(GROUP, len(SYNERGIES)),))


def _write_surrogate_data(folder: Path, model_file: Path) -> None:
    """Knee and ankle poses on a grid and the muscles' exact geometry there (surrogate data layout)."""
    from nmsm.io.storage import Table, write_storage
    from nmsm.model.muscle_analysis import analyze_motion

    knee, ankle = np.meshgrid(np.linspace(-0.35, 0.25, 9), np.linspace(-0.3, 0.3, 9))
    poses = np.zeros((knee.size, len(COORDINATES)))
    poses[:, 1], poses[:, 2] = knee.ravel(), ankle.ravel()
    time = (np.arange(knee.size) + 1) * 1e-3
    (folder / "IKData").mkdir(parents=True)
    table = Table(time=time, labels=COORDINATES, data=poses, name=TRIAL)
    write_storage(folder / "IKData" / f"{TRIAL}.sto", table)
    result = analyze_motion(model_file, table, coordinates=("q1", "q2"), engine="nmsm")
    result.write(folder / "MAData", TRIAL)


@functools.cache
def _folder() -> Path:
    """The model, ``.osimx`` and surrogate data of the module docstring (once per process)."""
    from nmsm.io.osimx import write_osimx

    path = Path(tempfile.mkdtemp(prefix="nmsm_check_term_leg_"))
    atexit.register(shutil.rmtree, path, ignore_errors=True)
    (path / "leg.osim").write_bytes(leg_model_xml())
    write_osimx(path / "leg.osimx", _osimx())
    _write_surrogate_data(path / "surrogate", path / "leg.osim")
    return path


# ------------------------------------------------------------------------------ the data
@attrs.frozen
class LegCase:
    """What every build of the problem shares: files, the model and the tracked data."""

    folder: Path
    model: Any
    mesh: Any
    references: dict[str, Any]
    initial_guess: dict[str, Any]
    weights: Any


@attrs.frozen
class _Files:
    """The initial-guess files the synergy controller reads (its ``synergyWeights.sto``)."""

    synergy_weights: Any


def _mesh() -> Any:
    from nmsm.core.transcription.mesh import Mesh

    return Mesh.uniform(3, 3)


@functools.cache
def leg_case() -> LegCase:
    """The files, the model adapter and the tracked data of the module docstring."""
    from nmsm.io.storage import Table
    from nmsm.tools.treatment.model_adapter import OsimTreatmentModel
    from nmsm.core.splines import ReferenceSplines

    folder = _folder()
    model = OsimTreatmentModel(folder / "leg.osim")
    mesh = _mesh()
    t = mesh.times("nodes") * DURATION
    dense = np.linspace(0.0, DURATION, 61)
    coordinates = ReferenceSplines(dense, COORDINATES, motion(dense))
    q, qd, qdd = (coordinates.values(dense, k) for k in range(3))
    tau = np.asarray(model.inverse_dynamics_function().map(dense.size)(q.T, qd.T, qdd.T)).T
    loads = ReferenceSplines(dense, tuple(model.load_label(c) for c in COORDINATES), tau)
    commands = 0.2 + 0.1 * np.column_stack([np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)])
    weights = Table(time=np.arange(1.0, len(SYNERGIES) + 1), labels=tuple(MUSCLES), data=WEIGHTS,
                    name="synergyWeights", source=folder / "synergyWeights.sto")
    initial_guess = {"synergyCommands": ReferenceSplines(t, SYNERGIES, commands), "loads": loads}
    references = {"coordinates": coordinates, "loads": loads,
                  "activations": ReferenceSplines(t, tuple(MUSCLES), commands @ WEIGHTS)}
    case = LegCase(folder, model, mesh, references, initial_guess, weights)
    references["ground_reactions"] = ReferenceSplines(t, sum(GRF_COLUMNS.values(), ()), _ground_reactions(case))
    return case


def _ground_reactions(case: LegCase) -> np.ndarray:
    """(nodes, 9) the contact surface's force (N), moment about the midfoot marker's floor
    point (N·m) and that point (m) on the mesh nodes of the tracked motion (the start)."""
    built = _build(case, "TO", [])
    nodes = built.context.at("nodes")
    columns = [nodes.ground_reaction_force(c) for c in GRF_COLUMNS["force"]]
    columns += [nodes.ground_reaction_moment(c) for c in GRF_COLUMNS["moment"]]
    columns.append(nodes.foot_ground_reaction("calcn")[2])
    problem = built.problem
    return np.asarray(problem.evaluate(cs.horzcat(*columns), problem.initial_scaled()))


def _build(case: LegCase, tool: str, terms: Sequence[Any]) -> Any:
    from nmsm.core.bounds import RangeRule, range_bounds
    from nmsm.core.controller_setup import ControllerSetup
    from nmsm.core.registry import get_registry
    from nmsm.tools.treatment.formulation import StateSetup, build_problem
    from nmsm.tools.treatment.problem_data import TreatmentData

    mesh = case.mesh
    setup = ControllerSetup(tool, case.model, mesh.times("collocation") * DURATION, DURATION, case.references,
                            case.initial_guess, model_file=case.folder / "leg.osim", osimx=case.folder / "leg.osimx",
                            trial_name=TRIAL, save_files=False, settings_file=case.folder / "check_term.xml")
    setup.node_times = mesh.times("nodes") * DURATION
    setup.extras["files"] = _Files(case.weights)
    registry = get_registry()
    torque = registry.get("controller", "torque", tool).from_settings({"coordinate_list": "q0"}, setup)
    synergy = registry.get("controller", "synergy", tool).from_settings(
        {"surrogate_model_coordinate_list": "q1 q2", "surrogate_model_data_directory": str(case.folder / "surrogate"),
         "surrogate_model_polynomial_degree": 3, "optimize_synergy_vectors": tool != "VO"}, setup)
    contacts = [c for item in registry.items("contact", tool) for c in item.cls.discover(setup)]
    coordinates = case.references["coordinates"]
    data = TreatmentData(tool, case.model, STATES, case.references, coordinates, DURATION, DURATION,
                         (DURATION, DURATION), controllers=[torque, synergy], contact_models=contacts)
    t = coordinates.time
    lo_q, hi_q = range_bounds(coordinates.values(t, 0, STATES), RangeRule(2))
    lo_v, hi_v = range_bounds(coordinates.values(t, 1, STATES), RangeRule(1.5))
    lo_a, hi_a = range_bounds(coordinates.values(t, 2, STATES), RangeRule(1))
    tn = mesh.times("nodes") * DURATION
    guess = np.hstack([coordinates.values(tn, 0, STATES), coordinates.values(tn, 1, STATES)])
    states = StateSetup(np.r_[lo_q, lo_v], np.r_[hi_q, hi_v], lo_a, hi_a, guess,
                        coordinates.values(mesh.times("collocation") * DURATION, 2, STATES))
    return build_problem(data, mesh, states, list(terms))


def build_leg_problem(terms: Sequence[Any], *, tool: str = "TO") -> Any:
    """The problem of the module docstring with ``terms`` (a
    :class:`~nmsm.tools.treatment.formulation.TreatmentProblem`)."""
    return _build(leg_case(), tool, terms)


__all__ = ["COORDINATES", "DURATION", "GRF_COLUMNS", "MUSCLES", "SYNERGIES", "LegCase", "build_leg_problem",
           "leg_case", "leg_model_xml", "motion"]

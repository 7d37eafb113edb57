"""A known-answer Neural Control Personalization case generated in code.

:func:`make_synthetic_ncp_case` writes into a folder everything ``nmsm run`` needs:

* ``legs.osim``: pelvis and two legs (pin hip, knee, ankle per side), eight Hill muscles
  per side (``<name>_r`` / ``<name>_l``) in ForceSet groups ``RightLeg`` and ``LeftLeg``;
* ``mtp/legs_mtp.osimx``: "MTP-personalized" optimal fiber and tendon slack lengths and
  forces (different from the model's, so NCP must read them);
* ``data/IDData/<trial>.sto`` and ``data/MAData/<trial>/`` (lengths, velocities, moment
  arms) for ``n_trials`` trials of 101 frames;
* ``mtp/muscleActivations/<trial>_muscleActivations.sto``: activations of all but the
  ``untracked`` muscles of each side (as MTP would have estimated them);
* ``NCPSettings.xml``: moment and activation tracking, the two synergy groups, bilateral
  symmetry on.

The truth: synergy vectors ``W`` (S, M) per side (mirror images of each other), commands
from spline nodes per trial (the left leg half a cycle behind the right), activations
``a = C W``, muscle forces through the personalized Hill model (:mod:`nmsm.model.hill`)
and joint moments ``M = Σ r F``. NCP should recover the vectors (up to ordering) and the
moments; :func:`run_synthetic_ncp` does it and reports the recovery.

Units: m, m/s, N, N·m, radians.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np
from lxml import etree

from nmsm.io.osimx import OsimxModel, OsimxMuscle, write_osimx
from nmsm.io.storage import table_from_columns, write_storage
from nmsm.model import hill

SETTINGS_FILE = "NCPSettings.xml"
MODEL_FILE = "legs.osim"
SIDES = ("r", "l")
GROUPS = {"r": "RightLeg", "l": "LeftLeg"}
COORDINATES = ("hip_flexion", "knee_angle", "ankle_angle")

#: muscle -> (first body, last body, F0 N, l_o m, l_ts m, alpha rad, moment arms (hip, knee, ankle) m)
MUSCLES: dict[str, tuple[str, str, float, float, float, float, tuple[float, float, float]]] = {
    "iliacus": ("pelvis", "thigh", 1500.0, 0.10, 0.10, 0.12, (0.035, 0.0, 0.0)),
    "glmax": ("pelvis", "thigh", 2500.0, 0.15, 0.07, 0.10, (-0.055, 0.0, 0.0)),
    "recfem": ("pelvis", "shank", 1800.0, 0.08, 0.35, 0.15, (0.035, -0.045, 0.0)),
    "hamstrings": ("pelvis", "shank", 2600.0, 0.10, 0.32, 0.20, (-0.06, 0.03, 0.0)),
    "vasti": ("thigh", "shank", 5000.0, 0.09, 0.20, 0.07, (0.0, -0.045, 0.0)),
    "gastroc": ("thigh", "foot", 3000.0, 0.06, 0.39, 0.25, (0.0, 0.025, -0.05)),
    "soleus": ("shank", "foot", 5500.0, 0.05, 0.25, 0.35, (0.0, 0.0, -0.045)),
    "tibant": ("shank", "foot", 1500.0, 0.07, 0.24, 0.10, (0.0, 0.0, 0.035)),
}
#: muscles without MTP activations (identifiable from the moments: alone on their coordinate's remainder)
UNTRACKED = ("iliacus", "soleus")
#: "MTP" personalization of (l_o, l_ts, F0) relative to the model's values
PERSONALIZATION = (1.08, 0.97, 1.15)


@attrs.frozen
class SyntheticNcpCase:
    """Files of a synthetic NCP case and its truth.

    ``true_weights`` (S, 8) per side, largest weight of each vector one, muscle order of
    :data:`MUSCLES`; ``true_activations`` per trial (101, 16) in NCP muscle order (right
    then left group); ``muscles`` that order.
    """

    folder: Path
    settings_file: Path
    model_file: Path
    osimx_file: Path
    trials: tuple[str, ...]
    muscles: tuple[str, ...]
    n_synergies: int
    true_weights: dict[str, np.ndarray]
    true_activations: tuple[np.ndarray, ...]
    true_moments: tuple[np.ndarray, ...]
    coordinates: tuple[str, ...]


# ------------------------------------------------------------------------------ the model
def _sub(parent: etree._Element, tag: str, text: str | None = None, **attributes: str) -> etree._Element:
    elem = etree.SubElement(parent, tag, **attributes)
    if text is not None:
        elem.text = text
    return elem


def _vec(values: Sequence[float]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _pin_joint(joints: etree._Element, name: str, coordinate: str, parent: str, child: str,
               translation: Sequence[float]) -> None:
    joint = _sub(joints, "PinJoint", name=name)
    _sub(joint, "socket_parent_frame", f"{parent}_offset")
    _sub(joint, "socket_child_frame", f"{child}_offset")
    coordinate_elem = _sub(_sub(joint, "coordinates"), "Coordinate", name=coordinate)
    _sub(coordinate_elem, "default_value", "0")
    _sub(coordinate_elem, "range", "-2 2")
    frames = _sub(joint, "frames")
    for frame, body, offset in ((f"{parent}_offset", parent, translation), (f"{child}_offset", child, (0, 0, 0))):
        f = _sub(frames, "PhysicalOffsetFrame", name=frame)
        _sub(f, "socket_parent", "/ground" if body == "ground" else f"/bodyset/{body}")
        _sub(f, "translation", _vec(offset))
        _sub(f, "orientation", "0 0 0")


def legs_model_xml() -> bytes:
    """OpenSim 4 model text: pelvis, two 3-segment legs, 16 muscles in two ForceSet groups."""
    root = etree.Element("OpenSimDocument", Version="40000")
    model = _sub(root, "Model", name="synthetic_legs")
    _sub(model, "Ground", name="ground")
    _sub(model, "gravity", "0 -9.80665 0")
    bodies = _sub(_sub(model, "BodySet", name="bodyset"), "objects")
    names = ["pelvis"] + [f"{segment}_{side}" for side in SIDES for segment in ("thigh", "shank", "foot")]
    for name in names:
        body = _sub(bodies, "Body", name=name)
        _sub(body, "mass", "5")
        _sub(body, "mass_center", "0 -0.1 0")
        _sub(body, "inertia", "0.05 0.01 0.05 0 0 0")
    joints = _sub(_sub(model, "JointSet", name="jointset"), "objects")
    _pin_joint(joints, "ground_pelvis", "pelvis_tilt", "ground", "pelvis", (0, 0.9, 0))
    for side in SIDES:
        z = 0.08 if side == "r" else -0.08
        _pin_joint(joints, f"hip_{side}", f"hip_flexion_{side}", "pelvis", f"thigh_{side}", (0, -0.07, z))
        _pin_joint(joints, f"knee_{side}", f"knee_angle_{side}", f"thigh_{side}", f"shank_{side}", (0, -0.4, 0))
        _pin_joint(joints, f"ankle_{side}", f"ankle_angle_{side}", f"shank_{side}", f"foot_{side}", (0, -0.4, 0))
    force_set = _sub(model, "ForceSet", name="forceset")
    forces = _sub(force_set, "objects")
    for side in SIDES:
        for muscle, (first, last, f0, lo, lts, alpha, _) in MUSCLES.items():
            m = _sub(forces, "Millard2012EquilibriumMuscle", name=f"{muscle}_{side}")
            _sub(m, "appliesForce", "true")
            path = _sub(m, "GeometryPath", name="path")
            points = _sub(_sub(path, "PathPointSet"), "objects")
            for k, body in enumerate((first, last)):
                body_name = body if body == "pelvis" else f"{body}_{side}"
                p = _sub(points, "PathPoint", name=f"{muscle}_{side}-P{k + 1}")
                _sub(p, "socket_parent_frame", f"/bodyset/{body_name}")
                _sub(p, "location", _vec((0.02 * (1 - 2 * k), -0.05 - 0.1 * k, 0)))
            _sub(m, "max_isometric_force", repr(f0))
            _sub(m, "optimal_fiber_length", repr(lo))
            _sub(m, "tendon_slack_length", repr(lts))
            _sub(m, "pennation_angle_at_optimal", repr(alpha))
    groups = _sub(force_set, "groups")
    for side in SIDES:
        group = _sub(groups, "ObjectGroup", name=GROUPS[side])
        _sub(group, "members", " ".join(f"{m}_{side}" for m in MUSCLES))
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


# ------------------------------------------------------------------------------ the truth
def _true_weights(n_synergies: int, rng: np.random.Generator) -> np.ndarray:
    """(S, 8) distinct non-negative vectors, each with a dominant muscle and a few others."""
    n = len(MUSCLES)
    weights = rng.uniform(0.0, 0.35, (n_synergies, n)) * (rng.uniform(size=(n_synergies, n)) < 0.5)
    dominant = rng.permutation(n)[:n_synergies]
    weights[np.arange(n_synergies), dominant] = 1.0
    return weights / weights.max(axis=1, keepdims=True)


def _command_nodes(n_synergies: int, n_nodes: int, shift: float, rng: np.random.Generator) -> np.ndarray:
    """(n_nodes, S) smooth positive periodic bumps, one peak per synergy, phase-shifted by ``shift``."""
    x = np.linspace(0.0, 1.0, n_nodes)[:, None]
    centers = (np.arange(n_synergies)[None, :] + 0.5) / n_synergies + shift + rng.uniform(-0.05, 0.05, (1, n_synergies))
    distance = np.abs(((x - centers) + 0.5) % 1.0 - 0.5)
    return 0.04 + 0.32 * np.exp(-0.5 * (distance / 0.12) ** 2)


def _kinematics(time: np.ndarray, side: int, lo: np.ndarray, lts: np.ndarray, alpha: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lengths, velocities (P, 8) and moment arms (P, 3, 8) over one cycle of ``time``."""
    duration = time[-1] - time[0]
    phase = 2 * np.pi * (time - time[0]) / duration + np.pi * side
    offsets = np.arange(len(MUSCLES))[None, :] * 0.7
    scale = lo * np.cos(alpha)
    lengths = lts + scale * (1.0 + 0.12 * np.sin(phase[:, None] + offsets))
    velocities = scale * 0.12 * np.cos(phase[:, None] + offsets) * (2 * np.pi / duration)
    arms0 = np.array([spec[6] for spec in MUSCLES.values()]).T  # (3, 8)
    modulation = 1.0 + 0.15 * np.sin(phase[:, None, None] + np.arange(3)[None, :, None])
    return lengths, velocities, arms0[None, :, :] * modulation


def make_synthetic_ncp_case(
    folder: str | os.PathLike[str],
    *,
    n_synergies: int = 3,
    n_trials: int = 2,
    n_points: int = 101,
    symmetric: bool = True,
    seed: int = 0,
) -> SyntheticNcpCase:
    """Write the case (see module docstring) into ``folder`` and return its truth."""
    from nmsm.tools.ncp.spline import DEFAULT_NODE_COUNT, commands_from_nodes

    folder = Path(folder)
    rng = np.random.default_rng(seed)
    (folder / "data" / "IDData").mkdir(parents=True, exist_ok=True)
    (folder / "mtp" / "muscleActivations").mkdir(parents=True, exist_ok=True)
    model_file = folder / MODEL_FILE
    model_file.write_bytes(legs_model_xml())
    base = np.array([[spec[2], spec[3], spec[4], spec[5]] for spec in MUSCLES.values()])  # F0, lo, lts, alpha
    f0 = base[:, 0] * PERSONALIZATION[2]
    lo = base[:, 1] * PERSONALIZATION[0]
    lts = base[:, 2] * PERSONALIZATION[1]
    alpha = base[:, 3]
    weights = {"r": _true_weights(n_synergies, rng)}
    weights["l"] = weights["r"].copy() if symmetric else _true_weights(n_synergies, rng)
    muscles = tuple(f"{m}_{side}" for side in SIDES for m in MUSCLES)
    coordinates = tuple(f"{c}_{side}" for side in SIDES for c in COORDINATES)
    trials, activations_all, moments_all = [], [], []
    for k in range(n_trials):
        trial = f"trial_{k + 1}"
        trials.append(trial)
        time = np.linspace(0.0, 1.1 + 0.05 * k, n_points)
        columns_len, columns_vel, arms_by_coordinate, moments, activations = {}, {}, {}, {}, {}
        for s, side in enumerate(SIDES):
            nodes = _command_nodes(n_synergies, DEFAULT_NODE_COUNT, 0.5 * s + 0.03 * k, rng)
            commands = commands_from_nodes(nodes, n_points)
            if commands.min() <= 0:
                raise RuntimeError("synthetic commands must stay positive")
            a = commands @ weights[side]  # (P, 8)
            lengths, velocities, arms = _kinematics(time, s, lo, lts, alpha)
            lt = hill.normalized_fiber_length(lengths, lo, lts, alpha)
            vt = hill.normalized_fiber_velocity(velocities, lo, alpha)
            force = hill.tendon_force(a, lt, vt, f0, alpha)
            m = hill.joint_moments(arms, force)  # (P, 3)
            for i, name in enumerate(MUSCLES):
                muscle = f"{name}_{side}"
                columns_len[muscle], columns_vel[muscle] = lengths[:, i], velocities[:, i]
                activations[muscle] = a[:, i]
            for j, coordinate in enumerate(COORDINATES):
                label = f"{coordinate}_{side}"
                moments[f"{label}_moment"] = m[:, j]
                arms_by_coordinate[label] = {f"{n}_{side}": arms[:, j, i] for i, n in enumerate(MUSCLES)}
        ma = folder / "data" / "MAData" / trial
        ma.mkdir(parents=True, exist_ok=True)
        write_storage(ma / f"{trial}_Length.sto", table_from_columns(time, {m: columns_len[m] for m in muscles}))
        write_storage(ma / f"{trial}_Velocity.sto", table_from_columns(time, {m: columns_vel[m] for m in muscles}))
        for coordinate in coordinates:
            side = coordinate[-1]
            cols = {m: (arms_by_coordinate[coordinate][m] if m.endswith(f"_{side}") else np.zeros(n_points)) for m in muscles}
            write_storage(ma / f"{trial}_MomentArm_{coordinate}.sto", table_from_columns(time, cols))
        write_storage(folder / "data" / "IDData" / f"{trial}.sto", table_from_columns(time, moments))
        tracked = [m for m in muscles if m.rsplit("_", 1)[0] not in UNTRACKED]
        write_storage(
            folder / "mtp" / "muscleActivations" / f"{trial}_muscleActivations.sto",
            table_from_columns(time, {m: activations[m] for m in tracked}),
        )
        activations_all.append(np.column_stack([activations[m] for m in muscles]))
        moments_all.append(np.column_stack([moments[f"{c}_moment"] for c in coordinates]))
    osimx_file = folder / "mtp" / "legs_mtp.osimx"
    personal = {}
    for side in SIDES:
        for i, name in enumerate(MUSCLES):
            muscle = f"{name}_{side}"
            personal[muscle] = OsimxMuscle(
                name=muscle, optimal_fiber_length=float(lo[i]), tendon_slack_length=float(lts[i]),
                max_isometric_force=float(f0[i]),
            )
    write_osimx(osimx_file, OsimxModel(name="synthetic_legs", associated_osim_model=f"../{MODEL_FILE}", muscles=personal))
    settings_file = folder / SETTINGS_FILE
    settings_file.write_bytes(_settings_xml(coordinates, n_synergies, symmetric))
    return SyntheticNcpCase(
        folder=folder,
        settings_file=settings_file,
        model_file=model_file,
        osimx_file=osimx_file,
        trials=tuple(trials),
        muscles=muscles,
        n_synergies=n_synergies,
        true_weights=weights,
        true_activations=tuple(activations_all),
        true_moments=tuple(moments_all),
        coordinates=coordinates,
    )


def _settings_xml(coordinates: Sequence[str], n_synergies: int, symmetric: bool) -> bytes:
    root = etree.Element("NMSMPipelineDocument", Version="1.5.0")
    tool = _sub(root, "NeuralControlPersonalizationTool", name="synthetic")
    _sub(tool, "results_directory", "results")
    _sub(tool, "input_model_file", MODEL_FILE)
    _sub(tool, "input_osimx_file", "mtp/legs_mtp.osimx")
    _sub(tool, "data_directory", "data")
    _sub(tool, "coordinate_list", " ".join(coordinates))
    _sub(tool, "activation_muscle_groups", "")
    _sub(tool, "normalized_fiber_length_muscle_groups", "")
    _sub(tool, "trial_prefixes", "")
    mtli = _sub(tool, "MuscleTendonLengthInitialization")
    _sub(mtli, "is_enabled", "false")
    _sub(tool, "mtp_results_directory", "mtp")
    _sub(tool, "enforce_bilateral_symmetry", "true" if symmetric else "false")
    terms = _sub(tool, "RCNLCostTermSet")
    for kind, error in (("moment_tracking", "1"), ("activation_tracking", "0.01")):
        term = _sub(terms, "RCNLCostTerm")
        _sub(term, "is_enabled", "true")
        _sub(term, "type", kind)
        _sub(term, "max_allowable_error", error)
    synergies = _sub(tool, "RCNLSynergySet")
    for side in SIDES:
        synergy = _sub(synergies, "RCNLSynergy")
        _sub(synergy, "muscle_group_name", GROUPS[side])
        _sub(synergy, "num_synergies", str(n_synergies))
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


# ------------------------------------------------------------------------------ recovery
def matched_cosine_similarity(estimated: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Cosine similarity of each true vector (rows of ``truth``) with its best-matched
    estimated vector (one-to-one matching maximizing the total similarity)."""
    from scipy.optimize import linear_sum_assignment

    e = estimated / np.maximum(np.linalg.norm(estimated, axis=1, keepdims=True), 1e-300)
    t = truth / np.maximum(np.linalg.norm(truth, axis=1, keepdims=True), 1e-300)
    similarity = t @ e.T
    rows, cols = linear_sum_assignment(-similarity)
    out = np.zeros(truth.shape[0])
    out[rows] = similarity[rows, cols]
    return out


@attrs.frozen
class SyntheticNcpResult:
    """Recovery of a synthetic case: cosine similarity per true vector and side, moment
    RMS per coordinate (N·m), activation RMS of all muscles against the truth."""

    case: SyntheticNcpCase
    cosine_similarity: dict[str, np.ndarray]
    moment_rms: np.ndarray
    activation_rms: float
    run: object


def run_synthetic_ncp(folder: str | os.PathLike[str], **options: object) -> SyntheticNcpResult:
    """Make the case in ``folder``, run NCP on its settings and compare with the truth.

    ``options`` go to :func:`make_synthetic_ncp_case` (``n_synergies``, ``symmetric``, ...)
    except ``print_level`` (IPOPT output, default 0).
    """
    from nmsm.tools.ncp.run import run_settings

    print_level = int(options.pop("print_level", 0))  # type: ignore[arg-type]
    case = make_synthetic_ncp_case(folder, **options)  # type: ignore[arg-type]
    run = run_settings(case.settings_file, print_level=print_level)
    layout = run.solution.layout
    similarity = {}
    for g, side in enumerate(SIDES):
        similarity[side] = matched_cosine_similarity(run.solution.group_weights(g), case.true_weights[side])
    errors = [a_est - a_true for a_est, a_true in zip(run.solution.all_activations(), case.true_activations)]
    order = [layout.muscles.index(m) for m in case.muscles]
    activation_rms = float(np.sqrt(np.mean(np.vstack([e[:, order] for e in errors]) ** 2)))
    return SyntheticNcpResult(
        case=case,
        cosine_similarity=similarity,
        moment_rms=run.metrics.moment_rms,
        activation_rms=activation_rms,
        run=run,
    )

"""Surrogate samples computed through OpenSim: Latin-hypercube poses around a motion.

Poses vary the ``varied`` coordinates (default: every coordinate of the reference motion,
as the original's ``sampleSurrogateKinematics``; pass the surrogate coordinate list to
keep every other coordinate at its reference value, which is what a surrogate of those
coordinates can represent) - rotational ones by ``angular_padding`` rad, the others by
``linear_padding`` m, per-coordinate overrides - clipped to the ranges of clamped
coordinates, ``samples_per_frame`` per reference frame. Locked coordinates are varied only
when named in ``varied``. Dependent (coupled) coordinates are then set by their couplers.

Moment arms fitted: ``"derivative"`` (default) = ``−dL/dq`` by central differences of
OpenSim path lengths with the coupler assembled, consistent with a polynomial's
derivative; ``"opensim"`` = OpenSim's ``computeMomentArm`` (what MuscleAnalysis writes;
"effective" where a coupler acts).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.core.progress import solve_progress
from nmsm.errors import InputError
from nmsm.io.storage import Table
from nmsm.model.surrogate import GeometrySamples
from nmsm.model.surrogate_sampling import coordinate_padding, latin_hypercube_poses

MOMENT_ARM_KINDS = ("derivative", "opensim")
#: with progress lines on, poses go to OpenSim in calls of at least this many poses ...
POSES_PER_CALL = 100
#: ... and at most this many calls, so a line can be printed between them
MAX_CALLS = 50


def _bridge(bridge: Any) -> Any:
    if bridge is not None:
        return bridge
    from nmsm.opensim_bridge import get_bridge

    return get_bridge()


def model_geometry_info(model_file: str | os.PathLike[str], bridge: Any = None) -> dict[str, Any]:
    """OpenSim's view of the model (coordinates, ranges, couplers, muscles, wrap objects)."""
    return _bridge(bridge).call("muscle_geometry_info", model=str(Path(model_file).resolve()))


def poses_around_motion(
    model_file: str | os.PathLike[str],
    motion: Table,
    *,
    angular_padding: float = np.deg2rad(10.0),
    linear_padding: float = 0.0,
    padding: Mapping[str, tuple[float, float]] | None = None,
    samples_per_frame: int = 25,
    seed: int | None = 0,
    varied: Sequence[str] | None = None,
    bridge: Any = None,
) -> tuple[tuple[str, ...], np.ndarray]:
    """Latin-hypercube poses around every frame of ``motion`` (model coordinates it names).

    Returns ``(coordinates, poses)``, ``poses`` ``(n_frames * samples_per_frame, n_c)`` in
    rad/m. Degrees in the motion are converted for rotational coordinates; a motion whose
    ``inDegrees`` header looks wrong for the model warns (:mod:`nmsm.io.motion_units`).
    ``varied``: the coordinates to sample (default all; see the module docstring).
    """
    from nmsm.io.motion_units import warn_implausible_angles

    info = model_geometry_info(model_file, bridge)
    names = info["coordinates"]
    rotational = {n: (float(lo), float(hi)) for n, r, (lo, hi) in zip(names, info["rotational"], info["ranges"]) if r}
    warn_implausible_angles(motion, rotational, file=motion.source)
    table = motion.to_radians(rotational)
    coords = tuple(c for c in table.labels if c in names)
    if not coords:
        raise InputError("no column names a model coordinate", file=motion.source, line=motion.label_line,
                         element="column labels", expected=f"coordinates of {model_file}")
    idx = [names.index(c) for c in coords]
    if varied is not None:
        missing = [c for c in varied if c not in coords]
        if missing:
            raise InputError(f"coordinates to vary are not columns of the motion: {', '.join(missing)}",
                             file=motion.source, line=motion.label_line, element="column labels",
                             expected="a motion holding every sampled coordinate")
    lower, upper = coordinate_padding(coords, [names[i] in rotational for i in idx], angular_padding, linear_padding,
                                      padding)
    if varied is None:
        fixed = [j for j, i in enumerate(idx) if info["locked"][i]]
    else:
        fixed = [j for j in range(len(coords)) if coords[j] not in varied]
    lower[fixed] = 0.0
    upper[fixed] = 0.0
    rmin = np.array([info["ranges"][i][0] if info["clamped"][i] else -np.inf for i in idx])
    rmax = np.array([info["ranges"][i][1] if info["clamped"][i] else np.inf for i in idx])
    poses = latin_hypercube_poses(table.columns(coords), lower, upper, rmin, rmax, samples_per_frame, seed)
    return coords, poses


def opensim_samples(
    model_file: str | os.PathLike[str],
    pose_coordinates: Sequence[str],
    poses: np.ndarray,
    surrogate_coordinates: Sequence[str],
    *,
    muscles: Sequence[str] | None = None,
    moment_arms: str = "derivative",
    bridge: Any = None,
) -> GeometrySamples:
    """Lengths and moment arms from OpenSim at ``poses`` ``(n, len(pose_coordinates))``.

    Coordinates not in ``pose_coordinates`` sit at their default values; dependent ones
    follow their couplers. ``muscles`` default: every muscle OpenSim finds.
    """
    if moment_arms not in MOMENT_ARM_KINDS:
        raise InputError(f"unknown moment-arm kind '{moment_arms}'", element="moment_arms",
                         expected=" or ".join(MOMENT_ARM_KINDS))
    from nmsm.model.muscle_analysis import check_model_names

    bridge = _bridge(bridge)
    path = str(Path(model_file).resolve())
    info = model_geometry_info(path, bridge)
    check_model_names("coordinates", surrogate_coordinates, info["coordinates"], str(model_file))
    if muscles is None:
        muscles = info["muscles"]
    check_model_names("muscles", muscles, info["muscles"], str(model_file))
    poses = np.atleast_2d(np.asarray(poses, dtype=float))
    progress = solve_progress("surrogate sampling")
    chunk = poses.shape[0] if progress is None else max(POSES_PER_CALL, -(-poses.shape[0] // MAX_CALLS))
    parts: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for start in range(0, poses.shape[0], chunk):
        block = poses[start:start + chunk]
        kw = dict(model=path, q=block, coordinates=list(pose_coordinates), muscles=list(muscles))
        if moment_arms == "derivative":
            out = bridge.call("muscle_length_gradients", wrt=list(surrogate_coordinates), **kw)
            lengths, arms = out["lengths"], -out["gradient"]
        else:
            lengths = bridge.call("muscle_lengths", **kw)
            arms = bridge.call("muscle_moment_arms", moment_arm_coordinates=list(surrogate_coordinates), **kw)
        parts.append((np.asarray(lengths), np.asarray(arms),
                      bridge.call("coupled_poses", model=path, q=block, coordinates=list(pose_coordinates))))
        if progress is not None and progress.due():
            progress.report_items(start + block.shape[0], poses.shape[0], "poses")
    lengths, arms, full = (np.concatenate([p[k] for p in parts]) for k in range(3))
    names = info["coordinates"]
    q = full[:, [names.index(c) for c in surrogate_coordinates]]
    return GeometrySamples(tuple(surrogate_coordinates), tuple(muscles), q, lengths, arms)

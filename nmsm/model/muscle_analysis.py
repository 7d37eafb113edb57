"""Muscle Analysis: muscle-tendon lengths, velocities and moment arms along a motion.

The equivalent of OpenSim's MuscleAnalysis for the NMSM data layout
(``MAData/<trial>/<trial>_Length.sto``, ``_Velocity.sto``, ``_MomentArm_<coord>.sto``,
OpenSim's MuscleAnalysis header: name line, ``version=1``, ``nRows``, ``nColumns``,
``inDegrees=no``, description, ``endheader``).

Poses: the motion's coordinate columns (rotational ones converted from degrees when the
file says ``inDegrees=yes``), unlisted coordinates at their default values, dependent
coordinates of couplers from their coupler (what OpenSim's ``Model.assemble`` does).
As OpenSim's AnalyzeTool sets them (``Coordinate::setValue``), a locked coordinate stays
at its default value whatever its column says and a clamped coordinate is held within its
range (:func:`analysis_poses`; both warn, naming the coordinates).
Coordinate speeds: derivative of an interpolating quintic spline with natural end
conditions (third and fourth derivatives zero at the ends) through each independent
coordinate, the spline OpenSim's AnalyzeTool differentiates (GCV spline, error variance
0); fewer than 6 frames use ``numpy.gradient``; locked coordinates do not move. Optional
low-pass filtering of the coordinates first, as AnalyzeTool's
``lowpass_cutoff_frequency_for_coordinates``.

Quantities (SI): length L (m); velocity ``V = Σ_c dL/dq_c q̇_c`` (m/s) over independent
coordinates, total derivatives through couplers; moment arm ``r_c = −dL/dq_c`` (m) of
path-point muscles. For a dependent (coupled) coordinate the file holds the moment arm of
its independent coordinate, as OpenSim's ``computeMomentArm`` reports it there. Muscles
computed by OpenSim take OpenSim's ``computeMomentArm`` (what MuscleAnalysis writes): where a
path wraps over more than one wrap object, or a wrap object limits its path to a quadrant,
OpenSim's path is not the shortest one, and the moment arm of the forces it applies
(``computeMomentArm``) is not ``−dL/dq`` of its length.

Engines (how the geometry is computed):

``"nmsm"``     exact path-point geometry in CasADi (:mod:`nmsm.model.muscle_paths`) for
               muscles without active wrapping; wrapping muscles from ``surrogate``
               (an error when it lacks one).
``"opensim"``  every muscle through the OpenSim bridge: path lengths, and central
               differences of them (coupler assembled) for the derivatives.
``"auto"``     (default) ``nmsm`` for path-point muscles; wrapping muscles from the
               surrogate when given, else from OpenSim.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.errors import InputError, ModelError
from nmsm.io.storage import Table, read_storage, write_storage

ENGINES = ("auto", "nmsm", "opensim")

#: description lines of OpenSim's MuscleAnalysis files
_DESCRIPTION = (
    "",
    "This analysis gathers basic information about muscles during a simulation (e.g., forces, tendon lengths, moment arms, etc).",
    "Units are S.I. units (second, meters, Newtons, ...)",
    "If the header above contains a line with 'inDegrees', this indicates whether rotational values are in degrees (yes) or radians (no).",
    "",
)


@attrs.frozen(eq=False)
class MuscleAnalysisResult:
    """Geometry along a motion.

    ``time`` ``(n,)`` s; ``lengths``, ``velocities`` ``(n, n_m)`` (m, m/s);
    ``moment_arms`` ``(n, n_m, n_c)`` m over ``coordinates``; ``sources`` maps each muscle
    to how it was computed (``"path"``, ``"surrogate"``, ``"opensim"``).
    """

    time: np.ndarray
    muscles: tuple[str, ...]
    coordinates: tuple[str, ...]
    lengths: np.ndarray
    velocities: np.ndarray
    moment_arms: np.ndarray
    sources: dict[str, str] = attrs.field(factory=dict)

    def table(self, quantity: str) -> Table:
        """``"Length"``, ``"Velocity"`` or ``"MomentArm_<coordinate>"`` as a Table."""
        if quantity == "Length":
            data = self.lengths
        elif quantity == "Velocity":
            data = self.velocities
        elif quantity.startswith("MomentArm_") and quantity[len("MomentArm_"):] in self.coordinates:
            data = self.moment_arms[:, :, self.coordinates.index(quantity[len("MomentArm_"):])]
        else:
            raise KeyError(f"unknown quantity '{quantity}'")
        return Table(time=self.time, labels=self.muscles, data=data, name=quantity, comments=_DESCRIPTION)

    def write(self, directory: str | os.PathLike[str], trial: str) -> list[Path]:
        """Write ``<directory>/<trial>/<trial>_Length.sto``, ``_Velocity.sto`` and one
        ``_MomentArm_<coord>.sto`` per coordinate; returns the paths. ``trial`` must be a
        plain file name (:func:`check_trial_name`)."""
        folder = Path(directory) / check_trial_name(trial)
        folder.mkdir(parents=True, exist_ok=True)
        quantities = ["Length", "Velocity"] + [f"MomentArm_{c}" for c in self.coordinates]
        return [write_storage(folder / f"{trial}_{q}.sto", self.table(q), name=q) for q in quantities]


def check_trial_name(trial: str) -> str:
    """``trial`` when it is a plain file name (no path separator, not empty, ``.`` or ``..``),
    so that files named after it stay in the output folder; else :class:`InputError`."""
    separators = {"/", "\\", os.sep} | ({os.altsep} if os.altsep else set())
    if not trial or trial.strip() in (".", "..") or any(s in trial for s in separators) or "\0" in trial:
        raise InputError(f"trial name '{trial}' is not a plain file name: the files named after it would not stay "
                         "in the output folder", element="trial",
                         expected="a name without path separators, other than '.' and '..'")
    return trial


# ---- poses --------------------------------------------------------------------------------
def motion_poses(model: Any, motion: Table) -> np.ndarray:
    """All model coordinates ``(n, n_q)`` (model order, rad/m) from a motion table.

    ``model`` is a parsed :class:`~nmsm.model.components.Model`. The columns are matched to
    the model's coordinates by :func:`nmsm.model.id_tool.motion_coordinates` (an error when
    none matches; warnings for absent coordinates, unknown columns and an implausible angle
    unit). Rotational columns are converted when the file is in degrees; missing coordinates
    take default values; dependent coordinates are set by their couplers.
    """
    from nmsm.model.id_tool import motion_coordinates

    q, _ = motion_coordinates(model, motion)
    if motion.in_degrees:
        rotational = [i for i, c in enumerate(model.coordinates) if c.is_rotational]
        q[:, rotational] = np.deg2rad(q[:, rotational])
    if not model.coupled_coordinates:
        return q
    from nmsm.model.coordinates import CoordinateMap

    return CoordinateMap(model).dependent_values(q)


#: a locked coordinate's column counts as moved when it leaves the default by more than this (rad or m)
POSE_TOLERANCE = 1e-6


def analysis_poses(model: Any, q: np.ndarray, *, source: Any = None) -> np.ndarray:
    """Poses ``(n, n_q)`` as OpenSim's AnalyzeTool sets them from ``q`` ``(n, n_q)``
    (model order, rad/m): locked coordinates at their default values, clamped coordinates
    held within their ranges, dependent coordinates recomputed by their couplers. Each
    change warns once, naming the coordinates, their frames and ``source`` (the motion)."""
    q = np.array(q, dtype=float)
    locked, clamped = [], []
    for i, c in enumerate(model.coordinates):
        if c.name in model.coupled_coordinates:
            continue
        if c.locked:
            moved = np.abs(q[:, i] - c.default_value) > POSE_TOLERANCE
            if moved.any():
                locked.append(f"{c.name} ({int(moved.sum())} frames)")
            q[:, i] = c.default_value
        elif c.clamped:
            outside = (q[:, i] < c.range[0]) | (q[:, i] > c.range[1])
            if outside.any():
                clamped.append(f"{c.name} ({int(outside.sum())} frames)")
            q[:, i] = np.clip(q[:, i], c.range[0], c.range[1])
    where = f"{source}: " if source is not None else ""
    if locked:
        warnings.warn(f"{where}locked coordinate(s) {', '.join(_some(locked))} differ from their default value in the "
                      "motion; they stay at the default, as OpenSim's tools set a motion", stacklevel=3)
    if clamped:
        warnings.warn(f"{where}clamped coordinate(s) {', '.join(_some(clamped))} leave their range in the motion; "
                      "they are held at the range's limits, as OpenSim's tools set a motion", stacklevel=3)
    if model.coupled_coordinates:
        from nmsm.model.coordinates import CoordinateMap

        q = CoordinateMap(model).dependent_values(q)
    return q


def _some(items: Sequence[str], limit: int = 5) -> list[str]:
    return list(items[:limit]) + ([f"and {len(items) - limit} more"] if len(items) > limit else [])


def coordinate_speeds(time: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``dq/dt`` ``(n, k)`` of ``q`` ``(n, k)`` sampled at ``time`` ``(n,)`` (see module docstring)."""
    from nmsm.model.signal import quintic_spline

    time = np.asarray(time, dtype=float)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    if len(time) < 2:
        return np.zeros_like(q)
    if len(time) < 6:
        return np.gradient(q, time, axis=0)
    return quintic_spline(time, q, time)[1]


def _filtered(time: np.ndarray, q: np.ndarray, lowpass_hz: float, table: Table) -> tuple[np.ndarray, np.ndarray]:
    """Padded, low-passed and splined coordinates and their speeds at ``time`` (AnalyzeTool's filtering)."""
    from nmsm.model.signal import lowpass_iir, pad, quintic_spline, uniform_interval

    n_pad = len(time) // 2
    values = lowpass_iir(pad(q, n_pad), uniform_interval(time, source=table.source), lowpass_hz)
    q_filtered, qdot, _ = quintic_spline(pad(time, n_pad), values, time)
    return q_filtered, qdot


# ---- engines ------------------------------------------------------------------------------
def _opensim_geometry(model_file: Path, model: Any, q: np.ndarray, muscles: Sequence[str], independent: Sequence[str],
                      bridge: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lengths ``(n, m)``, total gradients and ``computeMomentArm`` moment arms
    (``(n, m, len(independent))``) from OpenSim."""
    if bridge is None:
        from nmsm.opensim_bridge import get_bridge

        bridge = get_bridge()
    # the worker runs in its own working folder: a relative path would not find the model there
    out = bridge.call("muscle_length_gradients", model=str(Path(model_file).resolve()), q=q,
                      coordinates=model.coordinate_names,
                      muscles=list(muscles), wrt=list(independent), moment_arms=True)
    return out["lengths"], out["gradient"], out["moment_arms"]


def _nmsm_geometry(model: Any, q: np.ndarray, muscles: Sequence[str], independent: Sequence[str],
                   surrogate: Any) -> tuple[np.ndarray, np.ndarray]:
    """Lengths and total gradients from exact paths and the surrogate (:class:`MuscleGeometry`)."""
    from nmsm.model.muscle_geometry import MuscleGeometry
    from nmsm.model.muscle_paths import evaluate_function

    geometry = MuscleGeometry(model, muscles, independent, surrogate=surrogate)
    lengths, _, arms = evaluate_function(geometry.function(), q)
    return lengths, -arms


def check_model_names(kind: str, asked: Sequence[str], available: Sequence[str], model: str) -> None:
    """:class:`InputError` naming the ``kind`` (``"muscles"``, ``"coordinates"``) among ``asked``
    that are not in ``available``, the model (``model``: how to name it) and close matches."""
    from nmsm.io.names import close_matches

    pool = set(available)
    unknown = [name for name in asked if name not in pool]
    if not unknown:
        return
    described = []
    for name in unknown:
        close = close_matches(name, available, n=3)
        described.append(f"'{name}'" + (f" (did you mean {' or '.join(close)}?)" if close else ""))
    raise InputError(f"{kind} not in the model {model}: {', '.join(described)}", element=kind,
                     expected=f"names of the model's {kind}")


def _load_model(path: Path) -> Any:
    from nmsm.model import load_model

    return load_model(path)


def analyze_motion(
    model_file: str | os.PathLike[str],
    motion: Table | str | os.PathLike[str],
    *,
    muscles: Sequence[str] | None = None,
    coordinates: Sequence[str] | None = None,
    engine: str = "auto",
    surrogate: Any | None = None,
    bridge: Any | None = None,
    model: Any | None = None,
    lowpass_hz: float | None = None,
) -> MuscleAnalysisResult:
    """Lengths, velocities and moment arms of ``muscles`` along ``motion``.

    ``coordinates``: moment-arm coordinates (default: every model coordinate, as
    MuscleAnalysis with ``all``). ``surrogate``: a
    :class:`~nmsm.model.surrogate.SurrogateModel` for wrapping muscles. ``model``: the
    parsed model, when the caller has it. ``lowpass_hz``: low-pass the coordinates first
    as OpenSim's AnalyzeTool does (``lowpass_cutoff_frequency_for_coordinates``: pad by
    half the rows, third-order Butterworth forward and backward; :mod:`nmsm.model.signal`).
    """
    if engine not in ENGINES:
        raise InputError(f"unknown engine '{engine}'", element="engine", expected=" or ".join(ENGINES))
    model_file = Path(model_file)
    model = model if model is not None else _load_model(model_file)
    table = motion if isinstance(motion, Table) else read_storage(motion)
    names = model.coordinate_names
    muscles = tuple(model.muscle_names if muscles is None else muscles)
    check_model_names("muscles", muscles, model.muscle_names, f"{model.name} ({model.file})")
    coords = tuple(names if coordinates is None else coordinates)
    check_model_names("coordinates", coords, names, f"{model.name} ({model.file})")
    dependents = model.coupled_coordinates
    independent = [n for n in names if n not in dependents]

    q = motion_poses(model, table)
    columns = [names.index(c) for c in independent]
    if lowpass_hz is not None and lowpass_hz > 0:
        q[:, columns], qdot = _filtered(table.time, q[:, columns], lowpass_hz, table)
        if dependents:
            from nmsm.model.coordinates import CoordinateMap

            q = CoordinateMap(model).dependent_values(q)
    else:
        qdot = coordinate_speeds(table.time, q[:, columns])
    q = analysis_poses(model, q, source=table.source)
    qdot[:, [k for k, c in enumerate(independent) if model.coordinate(c).locked]] = 0.0

    from nmsm.model.muscle_paths import has_active_wrapping

    sources: dict[str, str] = {}
    uncovered = []
    for m in muscles:
        wraps = has_active_wrapping(model, model.muscle(m))
        if engine == "opensim":
            sources[m] = "opensim"
        elif not wraps:
            sources[m] = "path"
        elif surrogate is not None and m in surrogate.muscle_names:
            sources[m] = "surrogate"
        elif engine == "auto":
            sources[m] = "opensim"
        else:
            uncovered.append(m)
    if uncovered:
        raise ModelError(f"muscles with active wrapping not covered by the surrogate model: {', '.join(uncovered)}",
                         file=model.file, element="muscles",
                         expected="a surrogate model including them, or engine 'opensim' or 'auto'")

    n = table.n_rows
    lengths = np.zeros((n, len(muscles)))
    gradient = np.zeros((n, len(muscles), len(independent)))
    nmsm_cols = [i for i, m in enumerate(muscles) if sources[m] in ("path", "surrogate")]
    if nmsm_cols:
        chosen = [muscles[i] for i in nmsm_cols]
        lengths[:, nmsm_cols], gradient[:, nmsm_cols, :] = _nmsm_geometry(model, q, chosen, independent, surrogate)
    arms_independent = np.zeros_like(gradient)  # moment arms, (n, m, len(independent))
    osim_cols = [i for i, m in enumerate(muscles) if sources[m] == "opensim"]
    if osim_cols:
        chosen = [muscles[i] for i in osim_cols]
        lengths[:, osim_cols], gradient[:, osim_cols, :], arms_independent[:, osim_cols, :] = _opensim_geometry(
            model_file, model, q, chosen, independent, bridge)
    arms_independent[:, nmsm_cols, :] = -gradient[:, nmsm_cols, :]

    velocities = np.einsum("nmc,nc->nm", gradient, qdot)
    arms = np.zeros((n, len(muscles), len(coords)))
    for k, c in enumerate(coords):
        driver = c
        if c in dependents:
            driver = dependents[c].independent[0]
        arms[:, :, k] = arms_independent[:, :, independent.index(driver)]
    return MuscleAnalysisResult(table.time.copy(), muscles, coords, lengths, velocities, arms, sources)

"""Muscle geometry computed by OpenSim: path lengths, moment arms, MuscleAnalysis.

Worker commands (run inside the OpenSim worker; never import CasADi here).

Poses
-----
Every command takes ``q`` with shape ``(n_poses, n_coordinates)`` (m or rad) and
``coordinates``: the names of ``q``'s columns (default: every coordinate of the model in
CoordinateSet order). The state is built as follows, never through
``Coordinate.setValue`` (which clamps, honours locks and assembles):

1. every generalized coordinate starts at its ``default_value``;
2. the listed columns are written straight into the state's Q vector;
3. with ``apply_couplers=True`` (default) every CoordinateCouplerConstraint's dependent
   coordinate is overwritten by ``scale_factor * f(independent coordinates)``, the value
   OpenSim's ``Model.assemble`` gives it (the assembler tracks every independent
   coordinate and gives dependent ones no goal, so it moves only the dependent ones).

Muscles are found by walking the component tree (``Model.getMuscleList``), so muscles
declared under ``<components>`` (the 2D Moco model) are included; ``muscles`` selects and
orders them (default: all, in component order).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import opensim as osim

from nmsm.opensim_bridge.commands import command
from nmsm.opensim_bridge.commands.models import load_model

_Q_INDEX: dict[int, dict[str, int]] = {}


# ---- model helpers ----------------------------------------------------------------------
def _coordinate_names(model: Any) -> list[str]:
    cset = model.getCoordinateSet()
    return [cset.get(i).getName() for i in range(cset.getSize())]


def _muscles(model: Any, names: list[str] | None) -> list[Any]:
    found = {m.getName(): m for m in model.getMuscleList()}
    if names is None:
        return [m for m in model.getMuscleList()]
    missing = [n for n in names if n not in found]
    if missing:
        raise KeyError(f"muscles not in model {model.getName()!r}: {', '.join(missing)} (known: {', '.join(found)})")
    return [found[n] for n in names]


def _q_index(model: Any) -> dict[str, int]:
    """Coordinate name -> index in the state's Q vector (found by probing a scratch state)."""
    key = id(model)
    if key in _Q_INDEX:
        return _Q_INDEX[key]
    state = osim.State(model.getWorkingState())
    nq = state.getNQ()
    names = _coordinate_names(model)
    if nq != len(names):
        raise ValueError(
            f"model {model.getName()!r} has {nq} generalized coordinates in its state but "
            f"{len(names)} Coordinates (quaternion joints are not supported)"
        )
    cset = model.getCoordinateSet()
    index: dict[str, int] = {}
    for name in names:
        coord = cset.get(name)
        coord.setLocked(state, False)
        coord.setClamped(state, False)
        state.setQ(osim.Vector(nq, 0.0))
        coord.setValue(state, 0.731, False)
        q = np.array([state.getQ().get(i) for i in range(nq)])
        hits = np.flatnonzero(q != 0.0)
        if len(hits) != 1:
            raise RuntimeError(f"cannot locate coordinate {name!r} in the Q vector")
        index[name] = int(hits[0])
    _Q_INDEX[key] = index
    return index


def _couplers(model: Any) -> list[tuple[str, list[str], Any, float]]:
    """Enforced CoordinateCouplerConstraints: (dependent, independents, function, scale factor)."""
    out = []
    cset = model.getConstraintSet()
    for i in range(cset.getSize()):
        cc = osim.CoordinateCouplerConstraint.safeDownCast(cset.get(i))
        if cc is None or not cc.get_isEnforced():
            continue
        ind = cc.getIndependentCoordinateNames()
        scale = float(cc.getPropertyByName("scale_factor").toString())
        out.append((cc.getDependentCoordinateName(), [ind.get(k) for k in range(ind.getSize())], cc.getFunction(), scale))
    return out


class _PoseSetter:
    """Writes poses into a private state of ``model`` (see the module docstring)."""

    def __init__(self, model: Any, coordinates: list[str] | None, apply_couplers: bool) -> None:
        self.model = model
        self.state = osim.State(model.getWorkingState())
        self.index = _q_index(model)
        all_names = _coordinate_names(model)
        self.coordinates = list(all_names if coordinates is None else coordinates)
        unknown = [c for c in self.coordinates if c not in self.index]
        if unknown:
            raise KeyError(f"coordinates not in model {model.getName()!r}: {', '.join(unknown)}")
        cset = model.getCoordinateSet()
        self.nq = self.state.getNQ()
        self.default = np.zeros(self.nq)
        for name in all_names:
            self.default[self.index[name]] = cset.get(name).getDefaultValue()
        self.columns = np.array([self.index[c] for c in self.coordinates], dtype=int)
        self.couplers = _couplers(model) if apply_couplers else []

    def full_q(self, row: np.ndarray) -> np.ndarray:
        """Q vector (nq,) for one pose row (len(coordinates),), couplers applied."""
        q = self.default.copy()
        q[self.columns] = row
        return self.couple(q)

    def couple(self, q: np.ndarray) -> np.ndarray:
        for _ in range(max(1, len(self.couplers))):  # chained couplers settle in <= n passes
            for dependent, independents, function, scale in self.couplers:
                x = osim.Vector(len(independents), 0.0)
                for k, name in enumerate(independents):
                    x.set(k, float(q[self.index[name]]))
                q[self.index[dependent]] = scale * function.calcValue(x)
        return q

    def dependent_names(self) -> set[str]:
        return {c[0] for c in self.couplers}

    def set(self, q: np.ndarray) -> Any:
        """Write the full Q vector and realize Position; returns the state."""
        v = osim.Vector(self.nq, 0.0)
        for i in range(self.nq):
            v.set(i, float(q[i]))
        self.state.setQ(v)
        self.model.realizePosition(self.state)
        return self.state


def _poses(q: Any, n_columns: int) -> np.ndarray:
    arr = np.atleast_2d(np.asarray(q, dtype=float))
    if arr.shape[1] != n_columns:
        raise ValueError(f"q has {arr.shape[1]} columns, expected {n_columns} (one per listed coordinate)")
    return arr


def _lengths(muscles: list[Any], state: Any) -> np.ndarray:
    return np.array([m.getLength(state) for m in muscles])


#: |dL/dq| (m/rad or m/m) below which a muscle does not span a coordinate (round-off of a
#: length that does not depend on it is about 1e-12; moment arms that count are >= 1e-4)
SPAN_THRESHOLD = 1e-9


# ---- commands ----------------------------------------------------------------------------
@command
def muscle_geometry_info(model: str) -> dict[str, Any]:
    """What OpenSim sees of a model's muscle paths.

    Returns ``coordinates`` (CoordinateSet order), ``rotational``, ``ranges`` ((min, max)),
    ``clamped``, ``locked`` and ``defaults`` per coordinate,
    ``couplers`` (list of dicts: dependent, independents, scale_factor),
    ``muscles`` (component order) and per muscle ``path_points`` (concrete class per
    point) and ``wrap_objects`` (names of the path's wrap objects, empty when none).
    """
    osim_model = load_model(model)
    cset = osim_model.getCoordinateSet()
    info: dict[str, Any] = {
        "coordinates": _coordinate_names(osim_model),
        "rotational": [cset.get(i).getMotionType() == osim.Coordinate.Rotational for i in range(cset.getSize())],
        "ranges": [(cset.get(i).getRangeMin(), cset.get(i).getRangeMax()) for i in range(cset.getSize())],
        "clamped": [bool(cset.get(i).get_clamped()) for i in range(cset.getSize())],
        "locked": [bool(cset.get(i).get_locked()) for i in range(cset.getSize())],
        "defaults": [cset.get(i).getDefaultValue() for i in range(cset.getSize())],
        "couplers": [
            {"dependent": d, "independents": ind, "scale_factor": s} for d, ind, _, s in _couplers(osim_model)
        ],
        "muscles": [],
        "path_points": {},
        "wrap_objects": {},
    }
    for muscle in osim_model.getMuscleList():
        name = muscle.getName()
        info["muscles"].append(name)
        path = osim.GeometryPath.safeDownCast(muscle.getPath())
        if path is None:
            info["path_points"][name] = None
            info["wrap_objects"][name] = []
            continue
        pps = path.getPathPointSet()
        info["path_points"][name] = [pps.get(i).getConcreteClassName() for i in range(pps.getSize())]
        ws = path.getWrapSet()
        info["wrap_objects"][name] = [ws.get(i).getWrapObjectName() for i in range(ws.getSize())]
    return info


@command
def coupled_poses(model: str, q: Any, coordinates: list[str] | None = None) -> np.ndarray:
    """Poses completed as the other commands build them: ``(n_poses, n_model_coordinates)``.

    Columns in CoordinateSet order; unlisted coordinates at their defaults, dependent
    coordinates from their couplers.
    """
    osim_model = load_model(model)
    setter = _PoseSetter(osim_model, coordinates, True)
    names = _coordinate_names(osim_model)
    cols = [setter.index[n] for n in names]
    rows = _poses(q, len(setter.coordinates))
    return np.array([setter.full_q(r)[cols] for r in rows])


@command
def muscle_lengths(
    model: str,
    q: Any,
    coordinates: list[str] | None = None,
    muscles: list[str] | None = None,
    apply_couplers: bool = True,
) -> np.ndarray:
    """Muscle-tendon (path) lengths in m, shape ``(n_poses, n_muscles)``."""
    osim_model = load_model(model)
    setter = _PoseSetter(osim_model, coordinates, apply_couplers)
    chosen = _muscles(osim_model, muscles)
    rows = _poses(q, len(setter.coordinates))
    return np.array([_lengths(chosen, setter.set(setter.full_q(r))) for r in rows])


@command
def muscle_wrapping_active(
    model: str,
    q: Any,
    coordinates: list[str] | None = None,
    muscles: list[str] | None = None,
    apply_couplers: bool = True,
) -> np.ndarray:
    """Which wrap objects change each muscle's path: int bitmask ``(n_poses, n_muscles)``.

    Bit k is set when the path's k-th PathWrap (in its wrap set) puts wrap points
    (``PathWrapPoint``) into OpenSim's current path; 0 when no wrap object engages.
    """
    osim_model = load_model(model)
    setter = _PoseSetter(osim_model, coordinates, apply_couplers)
    chosen = _muscles(osim_model, muscles)
    paths = [osim.GeometryPath.safeDownCast(m.getPath()) for m in chosen]
    bits = []
    for path in paths:
        ws = path.getWrapSet() if path is not None else None
        bits.append({} if ws is None else {ws.get(k).getWrapObjectName(): 1 << k for k in range(ws.getSize())})
    rows = _poses(q, len(setter.coordinates))
    out = np.zeros((len(rows), len(chosen)), dtype=np.int64)
    for i, r in enumerate(rows):
        state = setter.set(setter.full_q(r))
        for j, path in enumerate(paths):
            if not bits[j]:
                continue
            current = path.getCurrentPath(state)
            for k in range(current.getSize()):
                point = osim.PathWrapPoint.safeDownCast(current.get(k))
                if point is not None:
                    out[i, j] |= bits[j].get(point.getWrapObject().getName(), 0)
    return out


@command
def muscle_moment_arms(
    model: str,
    q: Any,
    moment_arm_coordinates: list[str],
    coordinates: list[str] | None = None,
    muscles: list[str] | None = None,
    apply_couplers: bool = True,
) -> np.ndarray:
    """OpenSim's ``Muscle.computeMomentArm`` in m, shape ``(n_poses, n_muscles, n_ma_coords)``.

    Where a coupler constraint acts this is OpenSim's "effective" moment arm, which is
    not ``-dL/dq`` (see :func:`muscle_length_gradients`).
    """
    osim_model = load_model(model)
    setter = _PoseSetter(osim_model, coordinates, apply_couplers)
    chosen = _muscles(osim_model, muscles)
    cset = osim_model.getCoordinateSet()
    coords = [cset.get(c) for c in moment_arm_coordinates]
    rows = _poses(q, len(setter.coordinates))
    out = np.zeros((len(rows), len(chosen), len(coords)))
    for i, r in enumerate(rows):
        state = setter.set(setter.full_q(r))
        for j, m in enumerate(chosen):
            for k, c in enumerate(coords):
                out[i, j, k] = m.computeMomentArm(state, c)
    return out


@command
def muscle_length_gradients(
    model: str,
    q: Any,
    wrt: list[str],
    coordinates: list[str] | None = None,
    muscles: list[str] | None = None,
    step: float = 1e-5,
    apply_couplers: bool = True,
    moment_arms: bool = False,
) -> dict[str, np.ndarray]:
    """Central differences of OpenSim path lengths.

    For each pose and each coordinate in ``wrt`` the lengths are computed at
    ``q_c ± step`` (m or rad). When ``c`` is an independent coordinate of a coupler its
    dependent coordinates are recomputed at each perturbed pose (total derivative
    ``dL/dq_c`` along the coupler); a dependent coordinate named in ``wrt`` is perturbed
    alone (partial derivative).

    Spanned coordinates (without ``moment_arms``): the first, middle and last poses are
    differentiated for every muscle; a muscle whose ``|dL/dq_c|`` stays below ``SPAN_THRESHOLD`` at all three does not
    span ``c`` (its length changes only by round-off when ``c`` moves) and gets exactly 0
    there (at the other poses without being computed). With 86 leg muscles and 14 leg
    coordinates each muscle spans 1-4 of them.

    Returns ``lengths`` ``(n_poses, n_muscles)`` (m) and ``gradient``
    ``(n_poses, n_muscles, n_wrt)`` = dL/dq (m/rad or m/m). With ``moment_arms`` also
    ``moment_arms`` ``(n_poses, n_muscles, n_wrt)`` (m): ``Muscle.computeMomentArm`` (what
    OpenSim's MuscleAnalysis writes) for every coordinate whose gradient is not zero at
    some pose, zero for the others; it equals ``-gradient`` except where wrapping makes the
    path other than the shortest (two wrap objects, a quadrant) or a coupler acts.
    """
    osim_model = load_model(model)
    setter = _PoseSetter(osim_model, coordinates, apply_couplers)
    chosen = _muscles(osim_model, muscles)
    unknown = [c for c in wrt if c not in setter.index]
    if unknown:
        raise KeyError(f"wrt coordinates not in model: {', '.join(unknown)}")
    dependents = setter.dependent_names()
    rows = _poses(q, len(setter.coordinates))
    lengths = np.zeros((len(rows), len(chosen)))
    grad = np.zeros((len(rows), len(chosen), len(wrt)))
    # with ``moment_arms`` every pose is differentiated for every muscle: MuscleAnalysis's
    # moment arms are computed wherever a length changes at all, round-off included
    restrict = not moment_arms
    if not len(rows):
        probes: list[int] = []
    else:
        probes = sorted({0, len(rows) // 2, len(rows) - 1}) if restrict else list(range(len(rows)))
    spans = np.zeros((len(chosen), len(wrt)), dtype=bool)
    every = np.arange(len(chosen))

    def differentiate(i: int, which: np.ndarray, k: int, base: np.ndarray) -> None:
        name = wrt[k]
        subset = [chosen[j] for j in which]
        side = []
        for sign in (1.0, -1.0):
            qp = base.copy()
            qp[setter.index[name]] += sign * step
            if name not in dependents:
                qp = setter.couple(qp)
            side.append(_lengths(subset, setter.set(qp)))
        grad[i, which, k] = (side[0] - side[1]) / (2.0 * step)

    order = probes + [i for i in range(len(rows)) if i not in probes]
    for done, i in enumerate(order, start=1):
        base = setter.full_q(rows[i])
        lengths[i] = _lengths(chosen, setter.set(base))
        for k in range(len(wrt)):
            which = every if i in probes else np.flatnonzero(spans[:, k])
            if which.size:
                differentiate(i, which, k, base)
        if restrict and done == len(probes):
            spans = np.any(np.abs(grad[probes]) >= SPAN_THRESHOLD, axis=0)
            for p in probes:
                grad[p][~spans] = 0.0
    if not moment_arms:
        return {"lengths": lengths, "gradient": grad}
    cset = osim_model.getCoordinateSet()
    coords = [cset.get(c) for c in wrt]
    spans = np.abs(grad).max(axis=0) > 0.0  # (n_muscles, n_wrt)
    arms = np.zeros_like(grad)
    for i, r in enumerate(rows):
        state = setter.set(setter.full_q(r))
        for j, m in enumerate(chosen):
            for k in np.flatnonzero(spans[j]):
                arms[i, j, k] = m.computeMomentArm(state, coords[k])
    return {"lengths": lengths, "gradient": grad, "moment_arms": arms}


# ---- MuscleAnalysis ------------------------------------------------------------------------
@command
def run_muscle_analysis(
    model: str,
    coordinates_file: str,
    results_directory: str,
    name: str | None = None,
    muscles: list[str] | None = None,
    moment_arm_coordinates: list[str] | None = None,
    start_time: float | None = None,
    end_time: float | None = None,
    lowpass_cutoff_frequency: float = -1.0,
) -> list[str]:
    """Run OpenSim's MuscleAnalysis (AnalyzeTool) on a motion; returns the files written.

    Files are ``<results_directory>/<name>_MuscleAnalysis_<quantity>.sto`` (OpenSim's
    naming; ``name`` defaults to the model's name). The tool is built from a setup XML
    printed and re-loaded, because an AnalyzeTool assembled in Python does not run.
    Muscles under ``<components>`` are not seen by OpenSim's MuscleAnalysis.
    """
    model_path = str(Path(model).resolve())
    motion = str(Path(coordinates_file).resolve())
    out_dir = Path(results_directory).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    osim_model = osim.Model(model_path)
    table = osim.Storage(motion)
    t0 = table.getFirstTime() if start_time is None else float(start_time)
    t1 = table.getLastTime() if end_time is None else float(end_time)
    tool_name = name or osim_model.getName()

    analysis = osim.MuscleAnalysis()
    analysis.setName("MuscleAnalysis")
    analysis.setStartTime(t0)
    analysis.setEndTime(t1)
    analysis.setComputeMoments(True)
    analysis.setInDegrees(True)
    mlist = osim.ArrayStr()
    for m in muscles or ["all"]:
        mlist.append(m)
    analysis.setMuscles(mlist)
    clist = osim.ArrayStr()
    for c in moment_arm_coordinates or ["all"]:
        clist.append(c)
    analysis.setCoordinates(clist)

    tool = osim.AnalyzeTool()
    tool.setName(tool_name)
    tool.setModelFilename(model_path)
    tool.setCoordinatesFileName(motion)
    tool.setLowpassCutoffFrequency(float(lowpass_cutoff_frequency))
    tool.setInitialTime(t0)
    tool.setFinalTime(t1)
    tool.setResultsDir(str(out_dir))
    tool.getAnalysisSet().cloneAndAppend(analysis)
    setup = Path(os.getcwd()) / f"{tool_name}_muscle_analysis_setup.xml"
    tool.printToXML(str(setup))
    loaded = osim.AnalyzeTool(str(setup))
    if not loaded.run():
        raise RuntimeError(f"OpenSim AnalyzeTool failed for {motion}")
    return sorted(str(p) for p in out_dir.glob(f"{tool_name}_MuscleAnalysis_*.sto"))


@command
def gcv_spline_derivatives(motion: str, columns: list[str], order: int = 1) -> dict[str, np.ndarray]:
    """Derivatives of OpenSim's ``GCVSplineSet(5, Storage(motion))`` at the file's times.

    What AnalyzeTool differentiates to get speeds from a coordinates file (no filtering,
    values as in the file). Returns ``time`` ``(n,)`` and ``derivatives`` ``(n, len(columns))``.
    """
    storage = osim.Storage(str(Path(motion).resolve()))
    splines = osim.GCVSplineSet(5, storage)
    times = osim.ArrayDouble()
    storage.getTimeColumn(times)
    t = np.array([times.get(i) for i in range(times.getSize())])
    which = osim.StdVectorInt([0] * int(order))
    out = np.zeros((len(t), len(columns)))
    for j, name in enumerate(columns):
        spline = splines.get(name)
        out[:, j] = [spline.calcDerivative(which, osim.Vector(1, float(x))) for x in t]
    return {"time": t, "derivatives": out}

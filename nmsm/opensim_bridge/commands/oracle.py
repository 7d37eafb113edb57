"""OpenSim as the reference ("oracle") for nmsm's model: summaries, kinematics, inverse
dynamics, contact forces, functions, the ID tool, timings.

Runs in the worker only (imports ``opensim``, never CasADi). Arrays are numpy; coordinate
arrays are ``(k, n)`` in the model's CoordinateSet order and are written straight into
the state's Q and U vectors (no assembly, so constraints and locks do not move them).
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import numpy as np
import opensim as osim

from nmsm.opensim_bridge.commands import command

_MODELS: dict[tuple[str, float, str], Any] = {}
_KEEP: list[Any] = []


def _vec3(v: Any) -> list[float]:
    return [float(v.get(i)) for i in range(3)]


def _mat33(r: Any) -> list[list[float]]:
    return [[float(r.get(i, j)) for j in range(3)] for i in range(3)]


class _Prepared:
    """A loaded model with its state and the coordinate -> Q/U index maps."""

    def __init__(self, path: str, forces: str) -> None:
        model = osim.Model(str(path))
        if forces in ("no_muscles", "none"):
            for muscle in model.getComponentsList():
                if forces == "none" and osim.Force.safeDownCast(muscle) is not None:
                    osim.Force.safeDownCast(muscle).set_appliesForce(False)
                elif osim.Muscle.safeDownCast(muscle) is not None:
                    osim.Muscle.safeDownCast(muscle).set_appliesForce(False)
        state = model.initSystem()
        self.model = model
        self.state = state
        coords = model.getCoordinateSet()
        self.coordinates = [coords.get(i) for i in range(coords.getSize())]
        nq, nu = state.getNQ(), state.getNU()
        probe = osim.Vector(nq, 0.0)
        for k in range(nq):
            probe.set(k, k + 1.0)
        state.setQ(probe)
        self.q_index = [int(round(c.getValue(state) - 1.0)) for c in self.coordinates]
        probe_u = osim.Vector(nu, 0.0)
        for k in range(nu):
            probe_u.set(k, k + 1.0)
        state.setU(probe_u)
        self.u_index = [int(round(c.getSpeedValue(state) - 1.0)) for c in self.coordinates]
        self.nq, self.nu = nq, nu

    def set_state(self, q: np.ndarray, u: np.ndarray | None = None) -> None:
        qv = osim.Vector(self.nq, 0.0)
        for value, k in zip(q, self.q_index):
            qv.set(k, float(value))
        self.state.setQ(qv)
        uv = osim.Vector(self.nu, 0.0)
        if u is not None:
            for value, k in zip(u, self.u_index):
                uv.set(k, float(value))
        self.state.setU(uv)

    def u_vector(self, values: np.ndarray) -> Any:
        v = osim.Vector(self.nu, 0.0)
        for value, k in zip(values, self.u_index):
            v.set(k, float(value))
        return v


def _prepared(path: str, forces: str = "all") -> _Prepared:
    key = (str(Path(path).resolve()), os.path.getmtime(path), forces)
    prepared = _MODELS.get(key)
    if prepared is None:
        prepared = _Prepared(path, forces)
        _MODELS[key] = prepared
    return prepared


def _motion_type(c: Any) -> str:
    return {1: "rotational", 2: "translational", 3: "coupled"}.get(int(c.getMotionType()), "undefined")


@command
def oracle_model_summary(path: str) -> dict[str, Any]:
    """Names, orders and parameters of a model as OpenSim reads them."""
    p = _prepared(path)
    model, state = p.model, p.state
    bodies = model.getBodySet()
    markers = model.getMarkerSet()
    summary: dict[str, Any] = {
        "name": model.getName(),
        "gravity": _vec3(model.getGravity()),
        "coordinates": [c.getName() for c in p.coordinates],
        "q_index": p.q_index,
        "u_index": p.u_index,
        "coordinate_info": {
            c.getName(): {
                "motion": _motion_type(c), "range": [c.getRangeMin(), c.getRangeMax()],
                "default": c.getDefaultValue(), "locked": bool(c.getDefaultLocked()),
                "clamped": bool(c.getDefaultClamped()), "joint": c.getJoint().getName(),
            } for c in p.coordinates
        },
        "bodies": {
            bodies.get(i).getName(): {
                "mass": bodies.get(i).getMass(), "com": _vec3(bodies.get(i).getMassCenter()),
                "inertia": [bodies.get(i).getInertia().getMoments().get(k) for k in range(3)]
                + [bodies.get(i).getInertia().getProducts().get(k) for k in range(3)],
            } for i in range(bodies.getSize())
        },
        "markers": {
            markers.get(i).getName(): {
                "body": markers.get(i).getParentFrame().findBaseFrame().getName(),
                "location": _vec3(markers.get(i).get_location()),
            } for i in range(markers.getSize())
        },
    }
    muscles = {}
    for comp in model.getComponentsList():
        m = osim.Muscle.safeDownCast(comp)
        if m is None:
            continue
        path_points = m.getGeometryPath().getPathPointSet()
        muscles[m.getName()] = {
            "type": m.getConcreteClassName(),
            "max_isometric_force": m.getMaxIsometricForce(),
            "optimal_fiber_length": m.getOptimalFiberLength(),
            "tendon_slack_length": m.getTendonSlackLength(),
            "pennation_angle_at_optimal": m.getPennationAngleAtOptimalFiberLength(),
            "max_contraction_velocity": m.getMaxContractionVelocity(),
            "applies_force": bool(m.get_appliesForce()),
            "points": [path_points.get(k).getName() for k in range(path_points.getSize())],
            "point_types": [path_points.get(k).getConcreteClassName() for k in range(path_points.getSize())],
            "wraps": [m.getGeometryPath().getWrapSet().get(k).getWrapObjectName()
                      for k in range(m.getGeometryPath().getWrapSet().getSize())],
        }
    summary["muscles"] = muscles
    joints = model.getJointSet()
    summary["joints"] = {
        joints.get(i).getName(): {
            "type": joints.get(i).getConcreteClassName(),
            "parent": joints.get(i).getParentFrame().findBaseFrame().getName(),
            "child": joints.get(i).getChildFrame().findBaseFrame().getName(),
        } for i in range(joints.getSize())
    }
    groups = {}
    force_set = model.getForceSet()
    for i in range(force_set.getNumGroups()):
        group = force_set.getGroup(i)
        members = group.getMembers()
        groups[group.getName()] = [members.get(k).getName() for k in range(members.getSize())]
    summary["groups"] = groups
    wraps = {}
    for i in range(bodies.getSize()):
        body = bodies.get(i)
        wrap_set = body.getWrapObjectSet()
        for k in range(wrap_set.getSize()):
            w = wrap_set.get(k)
            entry = {"type": w.getConcreteClassName(), "body": body.getName(), "active": bool(w.get_active()),
                     "translation": _vec3(w.get_translation()), "rotation": _vec3(w.get_xyz_body_rotation()),
                     "quadrant": w.get_quadrant()}
            for cls, props in (("WrapCylinder", ("radius", "length")), ("WrapSphere", ("radius",)),
                               ("WrapTorus", ("inner_radius", "outer_radius"))):
                typed = getattr(osim, cls).safeDownCast(w)
                if typed is not None:
                    for prop in props:
                        entry[prop] = getattr(typed, f"get_{prop}")()
            ellipsoid = osim.WrapEllipsoid.safeDownCast(w)
            if ellipsoid is not None:
                entry["dimensions"] = _vec3(ellipsoid.get_dimensions())
            wraps[w.getName()] = entry
    summary["wrap_objects"] = wraps
    del state
    return summary


@command
def oracle_kinematics(path: str, q: np.ndarray) -> dict[str, np.ndarray]:
    """Marker positions ``(k, n_markers, 3)``, body origins ``(k, n_bodies, 3)`` and body
    rotations ``(k, n_bodies, 3, 3)`` (ground) for coordinate rows ``q`` ``(k, n)``."""
    p = _prepared(path)
    model, state = p.model, p.state
    markers = model.getMarkerSet()
    bodies = model.getBodySet()
    q = np.atleast_2d(np.asarray(q, dtype=float))
    out_m = np.zeros((q.shape[0], markers.getSize(), 3))
    out_o = np.zeros((q.shape[0], bodies.getSize(), 3))
    out_r = np.zeros((q.shape[0], bodies.getSize(), 3, 3))
    for k, row in enumerate(q):
        p.set_state(row)
        model.realizePosition(state)
        for i in range(markers.getSize()):
            out_m[k, i] = _vec3(markers.get(i).getLocationInGround(state))
        for i in range(bodies.getSize()):
            transform = bodies.get(i).getTransformInGround(state)
            out_o[k, i] = _vec3(transform.p())
            out_r[k, i] = _mat33(transform.R())
    return {"markers": out_m, "origins": out_o, "rotations": out_r,
            "marker_names": [markers.get(i).getName() for i in range(markers.getSize())],
            "body_names": [bodies.get(i).getName() for i in range(bodies.getSize())]}


@command
def oracle_inverse_dynamics(path: str, q: np.ndarray, u: np.ndarray, udot: np.ndarray,
                            loads: list[dict[str, Any]] | None = None, forces: str = "no_muscles") -> np.ndarray:
    """Generalized forces ``(k, n)`` (CoordinateSet order) from OpenSim's
    InverseDynamicsSolver. ``forces``: ``"no_muscles"`` (as the ID tool), ``"none"`` (only
    gravity and inertia) or ``"all"``. ``loads``: dicts with ``body`` and ``force``,
    ``point``, ``torque`` arrays ``(k, 3)`` in ground (force at point, plus torque)."""
    p = _prepared(path, forces)
    model, state = p.model, p.state
    solver = osim.InverseDynamicsSolver(model)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    u = np.atleast_2d(np.asarray(u, dtype=float))
    udot = np.atleast_2d(np.asarray(udot, dtype=float))
    body_set = model.getBodySet()
    nb = 1 + max([int(body_set.get(i).getMobilizedBodyIndex()) for i in range(body_set.getSize())] + [0])
    out = np.zeros(q.shape)
    for k in range(q.shape[0]):
        p.set_state(q[k], u[k])
        model.realizeDynamics(state)
        udot_k = p.u_vector(udot[k])
        tau = solver.solve(state, udot_k)  # gravity and the model's enabled forces
        if loads:
            # ID is linear in applied forces: add [solve with the loads alone] - [solve without forces]
            zero_bodies = osim.VectorOfSpatialVec(nb, osim.SpatialVec(osim.Vec3(0), osim.Vec3(0)))
            body_forces = osim.VectorOfSpatialVec(nb, osim.SpatialVec(osim.Vec3(0), osim.Vec3(0)))
            for load in loads:
                body = model.getBodySet().get(load["body"])
                index = int(body.getMobilizedBodyIndex())
                origin = np.array(_vec3(body.getPositionInGround(state)))
                force = np.asarray(load["force"][k], dtype=float)
                torque = np.asarray(load["torque"][k], dtype=float) + np.cross(
                    np.asarray(load["point"][k], dtype=float) - origin, force)
                old = body_forces.get(index)
                t_old = np.array(_vec3(old.get(0)))
                f_old = np.array(_vec3(old.get(1)))
                body_forces.set(index, osim.SpatialVec(osim.Vec3(*(t_old + torque)), osim.Vec3(*(f_old + force))))
            zero_mobility = osim.Vector(p.nu, 0.0)
            with_loads = solver.solve(state, udot_k, zero_mobility, body_forces)
            without = solver.solve(state, udot_k, zero_mobility, zero_bodies)
            tau = osim.Vector([tau.get(i) + with_loads.get(i) - without.get(i) for i in range(p.nu)])
        out[k] = [tau.get(i) for i in p.u_index]
    return out


@command
def oracle_contact_forces(path: str, q: np.ndarray, u: np.ndarray) -> dict[str, np.ndarray]:
    """Per SmoothSphereHalfSpaceForce (component order): the force (N, ground) and torque
    about the body origin (N m) on the sphere's body, ``(k, n_forces, 3)`` each."""
    p = _prepared(path)
    model, state = p.model, p.state
    elements = []
    for comp in model.getComponentsList():
        f = osim.SmoothSphereHalfSpaceForce.safeDownCast(comp)
        if f is not None:
            elements.append(f)
    q = np.atleast_2d(np.asarray(q, dtype=float))
    u = np.atleast_2d(np.asarray(u, dtype=float))
    forces = np.zeros((q.shape[0], len(elements), 3))
    torques = np.zeros((q.shape[0], len(elements), 3))
    for k in range(q.shape[0]):
        p.set_state(q[k], u[k])
        model.realizeVelocity(state)
        for i, element in enumerate(elements):
            values = element.getRecordValues(state)
            forces[k, i] = [values.get(j) for j in range(3)]
            torques[k, i] = [values.get(j) for j in range(3, 6)]
    return {"names": [e.getName() for e in elements], "forces": forces, "torques": torques,
            "constant_contact_force": [e.get_constant_contact_force() for e in elements]}


def _function(spec: dict[str, Any]) -> Any:
    kind = spec["type"]
    if kind == "Constant":
        return osim.Constant(float(spec["value"]))
    if kind == "LinearFunction":
        return osim.LinearFunction(float(spec["slope"]), float(spec["intercept"]))
    if kind == "PolynomialFunction":
        coefficients = osim.Vector(len(spec["coefficients"]), 0.0)
        for i, c in enumerate(spec["coefficients"]):
            coefficients.set(i, float(c))
        return osim.PolynomialFunction(coefficients)
    if kind == "MultiplierFunction":
        inner = _function(spec["function"])
        _KEEP.append(inner)  # OpenSim may take ownership: never let Python free it
        outer = osim.MultiplierFunction(inner, float(spec["scale"]))
        inner.thisown = False
        return outer
    if kind not in ("SimmSpline", "NaturalCubicSpline", "PiecewiseLinearFunction"):
        raise ValueError(f"unknown function type {kind}")
    if not hasattr(osim, kind):
        raise ValueError(f"this OpenSim build does not expose {kind} to Python")
    f = getattr(osim, kind)()
    for x, y in zip(spec["x"], spec["y"]):
        f.addPoint(float(x), float(y))
    return f


@command
def oracle_function_values(spec: dict[str, Any], x: np.ndarray) -> np.ndarray:
    """Value, first and second derivative ``(3, len(x))`` of an OpenSim function."""
    f = _function(spec)
    out = np.zeros((3, len(x)))
    for i, value in enumerate(np.asarray(x, dtype=float)):
        arg = osim.Vector(1, float(value))
        out[0, i] = f.calcValue(arg)
        for order in (1, 2):
            out[order, i] = f.calcDerivative(osim.StdVectorInt([0] * order), arg)
    return out


@command
def oracle_inverse_dynamics_tool(model_path: str, coordinates_file: str, output_file: str,
                                 external_loads_file: str | None = None, lowpass_hz: float = -1.0,
                                 time_range: tuple[float, float] | None = None) -> str:
    """Run OpenSim's InverseDynamicsTool (muscles excluded) and write ``output_file``."""
    model = osim.Model(str(model_path))
    tool = osim.InverseDynamicsTool()
    tool.setModel(model)
    tool.setCoordinatesFileName(str(coordinates_file))
    tool.setLowpassCutoffFrequency(float(lowpass_hz))
    excluded = osim.ArrayStr()
    excluded.append("Muscles")
    tool.setExcludedForces(excluded)
    if external_loads_file:
        tool.setExternalLoadsFileName(str(external_loads_file))
    storage = osim.Storage(str(coordinates_file))
    start, end = time_range if time_range else (storage.getFirstTime(), storage.getLastTime())
    tool.setStartTime(float(start))
    tool.setEndTime(float(end))
    out = Path(output_file)
    tool.setResultsDir(str(out.parent))
    tool.setOutputGenForceFileName(out.name)
    if not tool.run():
        raise RuntimeError("InverseDynamicsTool.run() returned false")
    return str(out)


@command
def oracle_storage_filter(coordinates_file: str, lowpass_hz: float) -> dict[str, np.ndarray]:
    """OpenSim's Storage pad(size/2) + lowpassIIR: times ``(m,)`` and data ``(m, ncol)``."""
    storage = osim.Storage(str(coordinates_file))
    storage.pad(storage.getSize() // 2)
    if lowpass_hz > 0:
        storage.lowpassIIR(float(lowpass_hz))
    times = osim.ArrayDouble()
    storage.getTimeColumn(times)
    n = storage.getSize()
    ncol = storage.getColumnLabels().getSize() - 1
    data = np.zeros((n, ncol))
    for i in range(n):
        row = storage.getStateVector(i).getData()
        data[i] = [row.get(j) for j in range(ncol)]
    return {"times": np.array([times.get(i) for i in range(times.getSize())]), "data": data}


@command
def oracle_time_inverse_dynamics(path: str, q: np.ndarray, u: np.ndarray, udot: np.ndarray,
                                 repeats: int = 3) -> dict[str, float]:
    """Seconds per InverseDynamicsSolver.solve with a fresh state per frame (muscles
    disabled, as the ID tool), timed inside the worker (best of ``repeats`` passes)."""
    p = _prepared(path, "no_muscles")
    model, state = p.model, p.state
    solver = osim.InverseDynamicsSolver(model)
    q = np.atleast_2d(q)
    u = np.atleast_2d(u)
    udot = np.atleast_2d(udot)
    udots = [p.u_vector(row) for row in udot]
    qs = []
    us = []
    for k in range(q.shape[0]):
        p.set_state(q[k], u[k])
        qs.append(osim.Vector(state.getQ()))
        us.append(osim.Vector(state.getU()))
    best = np.inf
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        for k in range(q.shape[0]):
            state.setQ(qs[k])
            state.setU(us[k])
            solver.solve(state, udots[k])
        best = min(best, time.perf_counter() - start)
    return {"seconds_per_frame": best / q.shape[0], "frames": int(q.shape[0])}


@command
def oracle_gcv_spline(times: np.ndarray, values: np.ndarray, at: np.ndarray, degree: int = 5) -> np.ndarray:
    """OpenSim's GCVSpline (zero error variance) of ``values`` ``(n,)`` over ``times``:
    value, first and second derivative at ``at``, ``(3, len(at))``."""
    import tempfile

    with tempfile.NamedTemporaryFile("w", suffix=".sto", delete=False, encoding="utf-8") as handle:
        handle.write(f"spline\nversion=1\nnRows={len(times)}\nnColumns=2\ninDegrees=no\nendheader\ntime\ty\n")
        for t, v in zip(times, values):
            handle.write(f"{float(t)!r}\t{float(v)!r}\n")
        name = handle.name
    try:
        splines = osim.GCVSplineSet(int(degree), osim.Storage(name))
    finally:
        os.unlink(name)
    f = splines.get(0)
    out = np.zeros((3, len(at)))
    for i, t in enumerate(np.asarray(at, dtype=float)):
        arg = osim.Vector(1, float(t))
        out[0, i] = f.calcValue(arg)
        out[1, i] = f.calcDerivative(osim.StdVectorInt([0]), arg)
        out[2, i] = f.calcDerivative(osim.StdVectorInt([0, 0]), arg)
    return out

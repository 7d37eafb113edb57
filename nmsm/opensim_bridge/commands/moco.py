"""OpenSim Moco: the 2D gait tracking problem of ``shared/anchors/moco_2d_track.py``.

:func:`moco_track_2d` sets up and solves the anchors' MocoTrack problem (spirit of
Moco's ``example2DWalking.cpp::gaitTracking()``) in the worker and returns the measured
wall time, iterations, objective and the solution's coordinates and ground reactions, so
a benchmark can run Moco and nmsm side by side under the same machine load. Every file
OpenSim writes goes to ``workdir`` (never next to the model or the data).
"""

from __future__ import annotations

import math
import os
import re
import time
from typing import Any

import numpy as np
import opensim as osim
from lxml import etree

from nmsm.io.xml_input import xml_parser
from nmsm.opensim_bridge.commands import command

#: the anchors' coordinate bounds (rad, m), keyed by state path
BOUNDS = {
    "/jointset/groundPelvis/pelvis_tilt/value": (-20 * math.pi / 180, -10 * math.pi / 180),
    "/jointset/groundPelvis/pelvis_tx/value": (0.0, 1.0),
    "/jointset/groundPelvis/pelvis_ty/value": (0.75, 1.25),
    "/jointset/hip_l/hip_flexion_l/value": (-10 * math.pi / 180, 60 * math.pi / 180),
    "/jointset/hip_r/hip_flexion_r/value": (-10 * math.pi / 180, 60 * math.pi / 180),
    "/jointset/knee_l/knee_angle_l/value": (-50 * math.pi / 180, 0.0),
    "/jointset/knee_r/knee_angle_r/value": (-50 * math.pi / 180, 0.0),
    "/jointset/ankle_l/ankle_angle_l/value": (-15 * math.pi / 180, 25 * math.pi / 180),
    "/jointset/ankle_r/ankle_angle_r/value": (-15 * math.pi / 180, 25 * math.pi / 180),
    "/jointset/lumbar/lumbar/value": (0.0, 20 * math.pi / 180),
}


def _components(model: Any, cls: Any) -> list[Any]:
    out = []
    for comp in model.getComponentsList():
        c = cls.safeDownCast(comp)
        if c is not None:
            out.append(c)
    return out


def _torque_model(model_file: str, workdir: str, reserve: float, residual: float) -> osim.ModelProcessor:
    """The anchors' torque-driven model: muscles removed (XML edit: they sit under
    ``<components>``), a CoordinateActuator ``tau_<coord>`` on every coordinate but lumbar."""
    tree = etree.parse(model_file, xml_parser(huge_tree=True))
    for parent in tree.getroot().iter():
        for child in list(parent):
            if child.tag == "DeGrooteFregly2016Muscle":
                parent.remove(child)
    path = os.path.join(workdir, "2D_gait_nomuscles.osim")
    tree.write(path)
    base = osim.ModelProcessor(path).process()
    base.initSystem()
    for c in _components(base, osim.Coordinate):
        if c.getName() == "lumbar":
            continue
        act = osim.CoordinateActuator(c.getName())
        act.setName("tau_" + c.getName())
        act.setOptimalForce(residual if c.getName().startswith("pelvis") else reserve)
        act.setMinControl(-math.inf)
        act.setMaxControl(math.inf)
        base.addForce(act)
    base.finalizeConnections()
    return osim.ModelProcessor(base)


@command
def moco_track_2d(model_file: str, coordinates_file: str, grf_file: str, workdir: str, mode: str = "muscle",
                  mesh_intervals: int = 50, tolerance: float = 1e-4, max_iterations: int = 1000, parallel: int = 2,
                  effort_weight: float = 10.0, state_weight: float = 1.0, grf_weight: float = 1.0,
                  final_time: float = 0.470089, reserve_optimal_force: float = 250.0,
                  residual_optimal_force: float = 50.0) -> dict[str, Any]:
    """Solve the anchors' MocoTrack 2D gait problem (``mode`` 'muscle' or 'torque').

    Returns ``wall_s`` (solve only), ``setup_s``, ``iterations``, ``objective``,
    ``objective_terms``, ``success``, ``status``, ``time`` (n,), ``coordinates`` (names),
    ``q`` (n, n_coords) rad/m, ``grf_labels`` and ``grf`` (n, 6): per side the summed
    SmoothSphereHalfSpaceForce forces ``ground_force_<r|l>_v<x|y|z>`` (N) on the feet,
    ``controls``/``control_names`` and ``settings``.
    """
    if mode not in ("muscle", "torque"):
        raise ValueError(f"mode must be 'muscle' or 'torque', not {mode!r}")
    os.makedirs(workdir, exist_ok=True)
    t_setup0 = time.perf_counter()
    with open(grf_file.replace(".sto", ".xml"), encoding="utf-8") as f:
        xml = f.read()
    xml = xml.replace(f"<datafile>{os.path.basename(grf_file)}</datafile>", f"<datafile>{grf_file}</datafile>")
    grf_xml = os.path.join(workdir, "referenceGRF_abs.xml")
    with open(grf_xml, "w", encoding="utf-8") as f:
        f.write(xml)
    if mode == "torque":
        mp = _torque_model(model_file, workdir, reserve_optimal_force, residual_optimal_force)
    else:
        mp = osim.ModelProcessor(model_file)

    track = osim.MocoTrack()
    track.setName(f"gaitTracking_{mode}")
    track.setModel(mp)
    tp = osim.TableProcessor(coordinates_file)
    tp.append(osim.TabOpLowPassFilter(6))
    track.setStatesReference(tp)
    track.set_states_global_tracking_weight(state_weight)
    track.set_allow_unused_references(True)
    track.set_track_reference_position_derivatives(True)
    track.set_apply_tracked_states_to_guess(True)
    track.set_initial_time(0.0)
    track.set_final_time(final_time)
    study = track.initialize()
    problem = study.updProblem()

    sym = osim.MocoPeriodicityGoal("symmetryGoal")
    problem.addGoal(sym)
    model = mp.process()
    model.initSystem()
    for c in _components(model, osim.Coordinate):
        n = c.getName()
        sv = [c.getStateVariableNames().get(i) for i in range(2)]
        if n.endswith("_r"):
            for s in sv:
                sym.addStatePair(osim.MocoPeriodicityGoalPair(s, re.sub("_r", "_l", s)))
        if n.endswith("_l"):
            for s in sv:
                sym.addStatePair(osim.MocoPeriodicityGoalPair(s, re.sub("_l", "_r", s)))
        if not (n.endswith("_l") or n.endswith("_r") or n.endswith("_tx")):
            for s in sv:
                sym.addStatePair(osim.MocoPeriodicityGoalPair(s, s))
    sym.addStatePair(osim.MocoPeriodicityGoalPair("/jointset/groundPelvis/pelvis_tx/speed"))
    sym.addControlPair(osim.MocoPeriodicityGoalPair("/lumbarAct"))
    n_muscles = 0
    for m in _components(model, osim.Muscle):
        n_muscles += 1
        s = m.getStateVariableNames().get(0)
        if m.getName().endswith("_r"):
            sym.addStatePair(osim.MocoPeriodicityGoalPair(s, re.sub("_r", "_l", s)))
        if m.getName().endswith("_l"):
            sym.addStatePair(osim.MocoPeriodicityGoalPair(s, re.sub("_l", "_r", s)))
    if mode == "torque":
        for ca in _components(model, osim.CoordinateActuator):
            if ca.getName() == "lumbarAct":
                continue
            p = ca.getAbsolutePathString()
            if p.endswith("_r"):
                sym.addControlPair(osim.MocoPeriodicityGoalPair(p, p[:-2] + "_l"))
            elif p.endswith("_l"):
                sym.addControlPair(osim.MocoPeriodicityGoalPair(p, p[:-2] + "_r"))

    effort = osim.MocoControlGoal.safeDownCast(problem.updGoal("control_effort"))
    effort.setWeight(effort_weight)
    if grf_weight != 0:
        ct = osim.MocoContactTrackingGoal("contact", grf_weight)
        ct.setExternalLoadsFile(grf_xml)
        right = osim.StdVectorString()
        for x in ("contactHeel_r", "contactFront_r"):
            right.append(x)
        left = osim.StdVectorString()
        for x in ("contactHeel_l", "contactFront_l"):
            left.append(x)
        ct.addContactGroup(right, "Right_GRF")
        ct.addContactGroup(left, "Left_GRF")
        ct.setProjection("plane")
        ct.setProjectionVector(osim.Vec3(0, 0, 1))
        problem.addGoal(ct)
    for path, (lo, hi) in BOUNDS.items():
        problem.setStateInfo(path, [lo, hi])

    solver = osim.MocoCasADiSolver.safeDownCast(study.updSolver())
    solver.set_num_mesh_intervals(int(mesh_intervals))
    solver.set_transcription_scheme("hermite-simpson")
    solver.set_verbosity(2)
    solver.set_optim_solver("ipopt")
    solver.set_optim_convergence_tolerance(float(tolerance))
    solver.set_optim_constraint_tolerance(float(tolerance))
    solver.set_optim_max_iterations(int(max_iterations))
    solver.set_parallel(int(parallel))
    settings = dict(mode=mode, mesh_intervals=int(mesh_intervals), transcription=solver.get_transcription_scheme(),
                    parallel=int(parallel), tolerance=float(tolerance), max_iterations=int(max_iterations),
                    effort_weight=effort_weight, state_weight=state_weight, grf_weight=grf_weight,
                    n_muscles=n_muscles, multibody_dynamics_mode=solver.get_multibody_dynamics_mode(),
                    finite_difference=solver.get_optim_finite_difference_scheme(),
                    hessian=solver.get_optim_hessian_approximation())
    setup_s = time.perf_counter() - t_setup0

    cwd = os.getcwd()
    os.chdir(workdir)
    try:
        t0 = time.perf_counter()
        sol = study.solve()
        wall = time.perf_counter() - t0
    finally:
        os.chdir(cwd)
    success = bool(sol.success())
    if not success:
        sol.unseal()
    sol.write(os.path.join(workdir, f"moco_{mode}_solution.sto"))
    names = sol.getObjectiveTermNames()
    terms = {names[i]: sol.getObjectiveTerm(names[i]) for i in range(len(names))}

    times = np.array(sol.getTimeMat()).ravel()
    coordinates = [c.getName() for c in _components(model, osim.Coordinate)]
    state_names = list(sol.getStateNames())
    states = np.array(sol.getStatesTrajectoryMat())
    q = np.column_stack([states[:, state_names.index(c.getStateVariableNames().get(0))]
                         for c in _components(model, osim.Coordinate)])
    paths = {f.getName(): f.getAbsolutePathString() for f in _components(model, osim.SmoothSphereHalfSpaceForce)}
    right = osim.StdVectorString()
    for x in ("contactHeel_r", "contactFront_r"):
        right.append(paths[x])
    left = osim.StdVectorString()
    for x in ("contactHeel_l", "contactFront_l"):
        left.append(paths[x])
    table = osim.createExternalLoadsTableForGait(model, sol, right, left)
    labels = ["ground_force_r_vx", "ground_force_r_vy", "ground_force_r_vz",
              "ground_force_l_vx", "ground_force_l_vy", "ground_force_l_vz"]
    table_labels = list(table.getColumnLabels())
    grf = np.column_stack([table.getDependentColumn(lab).to_numpy() for lab in labels if lab in table_labels])
    controls = np.array(sol.getControlsTrajectoryMat())
    return dict(wall_s=wall, setup_s=setup_s, iterations=int(sol.getNumIterations()),
                objective=float(sol.getObjective()), objective_terms=terms, success=success,
                status=str(sol.getStatus()), time=times, coordinates=coordinates, q=q,
                grf_labels=[lab for lab in labels if lab in table_labels], grf=grf,
                control_names=list(sol.getControlNames()), controls=controls, settings=settings)


@command
def moco_states_reference(coordinates_file: str, cutoff_frequency: float = 6.0) -> dict[str, Any]:
    """The states reference MocoTrack tracks: ``coordinates_file`` through
    ``TableProcessor`` + ``TabOpLowPassFilter(cutoff_frequency)`` (Hz; OpenSim pads,
    filters and resamples). Returns ``time`` (n,), ``labels`` (state paths), ``data`` (n, k)."""
    tp = osim.TableProcessor(coordinates_file)
    tp.append(osim.TabOpLowPassFilter(float(cutoff_frequency)))
    table = tp.process()
    labels = list(table.getColumnLabels())
    data = np.column_stack([table.getDependentColumn(lab).to_numpy() for lab in labels])
    return dict(time=np.array(table.getIndependentColumn()), labels=labels, data=data)


@command
def muscle_tendon_forces(model_file: str, coordinates: list[str], q: np.ndarray, u: np.ndarray,
                         activation: np.ndarray, excitation: np.ndarray | None = None) -> dict[str, Any]:
    """OpenSim's muscle outputs at given states: ``q``, ``u`` (k, len(coordinates)) rad, m,
    rad/s, m/s; ``activation`` (k, M) for the model's muscles in component order (state
    ``activation`` set directly). Returns ``names``, ``tendon_force`` (k, M) N,
    ``normalized_fiber_length`` and ``normalized_fiber_velocity`` (k, M); with ``excitation``
    (k, M) (the muscles' controls, prescribed by a PrescribedController of constants) also
    ``activation_derivative`` (k, M) 1/s, the activation state's derivative."""
    model = osim.Model(model_file)
    q, u, activation = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, u, activation))
    controls = None
    if excitation is not None:
        excitation = np.atleast_2d(np.asarray(excitation, dtype=float))
        model.initSystem()
        controller = osim.PrescribedController()
        for muscle in _components(model, osim.Muscle):
            controller.addActuator(muscle)
            controller.prescribeControlForActuator(muscle.getName(), osim.Constant(0.0))
        model.addController(controller)
    state = model.initSystem()
    coords = {c.getName(): c for c in _components(model, osim.Coordinate)}
    muscles = _components(model, osim.Muscle)
    if excitation is not None:
        functions = controller.get_ControlFunctions()
        controls = [osim.Constant.safeDownCast(functions.get(m)) for m in range(len(muscles))]
    if activation.shape[1] != len(muscles):
        raise ValueError(f"activation has {activation.shape[1]} columns, the model has {len(muscles)} muscles")
    names = ["tendon_force", "normalized_fiber_length", "normalized_fiber_velocity"]
    out = {k: np.zeros((q.shape[0], len(muscles))) for k in names + (["activation_derivative"] if controls else [])}
    for k in range(q.shape[0]):
        state.setTime(float(k))  # a new time invalidates every cached stage (controls included)
        for j, name in enumerate(coordinates):
            coords[name].setValue(state, float(q[k, j]), False)
            coords[name].setSpeedValue(state, float(u[k, j]))
        for m, muscle in enumerate(muscles):
            muscle.setActivation(state, float(activation[k, m]))
            if controls:
                controls[m].setValue(float(excitation[k, m]))
        model.realizeAcceleration(state) if controls else model.realizeDynamics(state)
        for m, muscle in enumerate(muscles):
            out["tendon_force"][k, m] = muscle.getTendonForce(state)
            out["normalized_fiber_length"][k, m] = muscle.getNormalizedFiberLength(state)
            out["normalized_fiber_velocity"][k, m] = muscle.getNormalizedFiberVelocity(state)
            if controls:
                out["activation_derivative"][k, m] = muscle.getStateVariableDerivativeValue(state, "activation")
    return dict(names=[m.getName() for m in muscles], **out)

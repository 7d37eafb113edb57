"""OpenSim inverse kinematics and body scaling (worker side; imports opensim, never CasADi).

``opensim_inverse_kinematics``  OpenSim's InverseKinematicsSolver frame by frame, as the
                                InverseKinematicsTool runs it; returns coordinates (CoordinateSet
                                order, rad / m), per-marker errors (m) and the solve time.
``opensim_inverse_kinematics_tool``  the InverseKinematicsTool itself writing a ``.mot``
                                (timed inside the worker: model load, solve, writing).
``opensim_scale_bodies``        ``Model.scale`` with uniform factors on chosen bodies (as JMP
                                scales a body); returns the muscle properties it changed.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import opensim as osim

from nmsm.opensim_bridge.commands import command


def _marker_weights(weights: dict[str, float] | None) -> Any:
    weight_set = osim.SetMarkerWeights()
    for name, weight in (weights or {}).items():
        weight_set.cloneAndAppend(osim.MarkerWeight(str(name), float(weight)))
    return weight_set


def _frame_rows(times: np.ndarray, time_range: tuple[float, float] | None) -> np.ndarray:
    if time_range is None:
        return np.arange(times.size)
    start, end = time_range
    tol = 1e-9
    return np.flatnonzero((times >= start - tol) & (times <= end + tol))


@command
def opensim_inverse_kinematics(model: str, marker_file: str, marker_weights: dict[str, float] | None = None,
                               time_range: tuple[float, float] | None = None, accuracy: float = 1e-5,
                               constraint_weight: float = math.inf) -> dict[str, Any]:
    """OpenSim IK of ``marker_file`` with ``model``.

    ``marker_weights``: marker -> weight (only these markers are used, as the IK tool does
    with an IKTaskSet); ``None`` uses every marker of both the file and the model with weight 1.
    Returns ``time (F,)``, ``coordinates`` (names, CoordinateSet order), ``q (F, n)`` in rad /
    m, ``markers`` (names of the markers in use), ``errors (F, n_markers)`` (m, NaN when a
    marker is missing in a frame) and ``solve_seconds`` (assemble + track loop only).
    """
    osim_model = osim.Model(str(model))
    state = osim_model.initSystem()
    reference = osim.MarkersReference(str(marker_file), _marker_weights(marker_weights))
    coordinate_references = osim.SimTKArrayCoordinateReference()
    solver = osim.InverseKinematicsSolver(osim_model, reference, coordinate_references, float(constraint_weight))
    solver.setAccuracy(float(accuracy))
    table = reference.getMarkerTable()
    times = np.array([table.getIndependentColumn()[i] for i in range(table.getNumRows())])
    rows = _frame_rows(times, time_range)
    coordinates = osim_model.getCoordinateSet()
    names = [coordinates.get(i).getName() for i in range(coordinates.getSize())]
    q = np.zeros((rows.size, len(names)))
    errors: list[list[float]] = []
    marker_names: list[str] = []
    start = time.perf_counter()
    for k, row in enumerate(rows):
        state.setTime(float(times[row]))
        if k == 0:
            solver.assemble(state)
            marker_names = [solver.getMarkerNameForIndex(i) for i in range(solver.getNumMarkersInUse())]
        else:
            solver.track(state)
        values = osim.SimTKArrayDouble()
        solver.computeCurrentMarkerErrors(values)
        errors.append([values.getElt(i) for i in range(values.size())])
        for i in range(len(names)):
            q[k, i] = coordinates.get(i).getValue(state)
    seconds = time.perf_counter() - start
    return {"time": times[rows], "coordinates": names, "q": q, "markers": marker_names,
            "errors": np.array(errors, dtype=float), "solve_seconds": seconds}


@command
def opensim_inverse_kinematics_tool(model: str, marker_file: str, output_motion: str,
                                    marker_weights: dict[str, float] | None = None,
                                    time_range: tuple[float, float] | None = None,
                                    accuracy: float = 1e-5) -> dict[str, Any]:
    """Run OpenSim's InverseKinematicsTool and write ``output_motion`` (.mot, degrees).

    Returns ``seconds`` (the whole tool run inside the worker: model initialization, solve,
    writing) and ``output`` (the motion file path).
    """
    start = time.perf_counter()
    osim_model = osim.Model(str(model))
    tool = osim.InverseKinematicsTool()
    tool.setModel(osim_model)
    tool.setMarkerDataFileName(str(marker_file))
    tasks = tool.getIKTaskSet()
    for name, weight in (marker_weights or {}).items():
        task = osim.IKMarkerTask()
        task.setName(str(name))
        task.setApply(True)
        task.setWeight(float(weight))
        tasks.cloneAndAppend(task)
    if time_range is None:
        trc = osim.TimeSeriesTableVec3(str(marker_file))
        column = trc.getIndependentColumn()
        time_range = (column[0], column[len(column) - 1])
    tool.setStartTime(float(time_range[0]))
    tool.setEndTime(float(time_range[1]))
    tool.set_accuracy(float(accuracy))
    out = Path(output_motion)
    tool.setResultsDir(str(out.parent))
    tool.setOutputMotionFileName(str(out))
    if not tool.run():
        raise RuntimeError("InverseKinematicsTool.run() returned false")
    return {"seconds": time.perf_counter() - start, "output": str(out)}


@command
def opensim_scale_bodies(model: str, output: str, factors: dict[str, float],
                         preserve_mass_distribution: bool = True) -> dict[str, Any]:
    """``Model.scale`` with a uniform factor per body (others 1), as JMP's body scaling does,
    and print the scaled model to ``output``.

    Returns ``muscles``: name -> (optimal_fiber_length, tendon_slack_length) after scaling
    (OpenSim rescales both by the change of the path length in the default pose).
    """
    osim_model = osim.Model(str(model))
    state = osim_model.initSystem()
    scale_set = osim.ScaleSet()
    for body, factor in factors.items():
        scale = osim.Scale()
        scale.setSegmentName(str(body))
        scale.setScaleFactors(osim.Vec3(float(factor)))
        scale.setApply(True)
        scale_set.cloneAndAppend(scale)
    if not osim_model.scale(state, scale_set, bool(preserve_mass_distribution), -1.0):
        raise RuntimeError("Model.scale returned false")
    osim_model.printToXML(str(output))
    muscles = osim_model.getMuscles()
    values = {}
    for i in range(muscles.getSize()):
        m = muscles.get(i)
        values[m.getName()] = (m.getOptimalFiberLength(), m.getTendonSlackLength())
    return {"muscles": values, "output": str(output)}

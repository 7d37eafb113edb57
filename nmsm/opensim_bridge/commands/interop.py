"""Worker commands checking models written by :mod:`nmsm.interop` (``nmsm export``)."""

from __future__ import annotations

from typing import Any

import opensim as osim

from nmsm.opensim_bridge.commands import command


@command
def exported_model_summary(path: str) -> dict[str, Any]:
    """Load and initialize an exported model; its muscles' parameters as OpenSim reads them,
    its contact geometry and forces by type, and the total contact force (N, ground) of
    its SmoothSphereHalfSpaceForces in the default pose."""
    model = osim.Model(str(path))
    state = model.initSystem()
    muscles = {}
    for muscle in model.getMuscles():
        entry = {"max_isometric_force": muscle.getMaxIsometricForce(),
                 "optimal_fiber_length": muscle.getOptimalFiberLength(),
                 "tendon_slack_length": muscle.getTendonSlackLength()}
        for name in ("activation_time_constant", "deactivation_time_constant"):
            if muscle.hasProperty(name):
                entry[name] = float(osim.PropertyHelper.getValueDouble(muscle.getPropertyByName(name)))
        muscles[muscle.getName()] = entry
    geometry = model.getContactGeometrySet()
    kinds: dict[str, int] = {}
    for force in model.getForceSet():
        kinds[force.getConcreteClassName()] = kinds.get(force.getConcreteClassName(), 0) + 1
    model.realizeDynamics(state)
    total = [0.0, 0.0, 0.0]
    for force in model.getForceSet():
        if force.getConcreteClassName() != "SmoothSphereHalfSpaceForce":
            continue
        values = force.getRecordValues(state)
        for k in range(3):
            total[k] += values.get(k)  # sphere force x, y, z
    return {"muscles": muscles, "contact_geometry": geometry.getSize(), "forces": kinds, "contact_force": total}

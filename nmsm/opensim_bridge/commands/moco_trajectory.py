"""Worker commands reading Moco trajectory files with OpenSim's own ``MocoTrajectory``."""

from __future__ import annotations

from typing import Any

import numpy as np
import opensim as osim

from nmsm.opensim_bridge.commands import command


@command
def moco_trajectory_summary(path: str, compare_to: str | None = None) -> dict[str, Any]:
    """Open ``path`` as ``opensim.MocoTrajectory``; its state and control names, times (s) and
    values as OpenSim reads them, and, with ``compare_to`` (another trajectory file),
    ``compareContinuousVariablesRMS`` of the two (OpenSim's time-normalized RMS over
    states, controls, multipliers and derivatives)."""
    trajectory = osim.MocoTrajectory(str(path))
    out: dict[str, Any] = {
        "state_names": list(trajectory.getStateNames()),
        "control_names": list(trajectory.getControlNames()),
        "time": np.array(trajectory.getTimeMat(), dtype=float),
        "states": np.array(trajectory.getStatesTrajectoryMat(), dtype=float),
        "controls": np.array(trajectory.getControlsTrajectoryMat(), dtype=float),
    }
    if compare_to is not None:
        out["rms"] = float(trajectory.compareContinuousVariablesRMS(osim.MocoTrajectory(str(compare_to))))
    return out

"""The bridge to OpenSim 4.6: OpenSim runs only in a worker subprocess.

Use it to run OpenSim's IK, ID and MuscleAnalysis for users, to upgrade old model
files, to sample muscle geometry, and to check nmsm's numbers in tests. This package
never imports CasADi or OpenSim in the calling process.
"""

from nmsm.opensim_bridge.client import OpenSimBridge, get_bridge, opensim_available

__all__ = ["OpenSimBridge", "get_bridge", "opensim_available"]

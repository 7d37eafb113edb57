"""nmsm: the Neuromusculoskeletal Modeling Pipeline in Python.

Personalize an OpenSim model (joints, muscle-tendon properties, neural control, foot
contact) from one patient's lab data, then predict and optimize treatment by direct
collocation. Derivatives come from CasADi automatic differentiation.

This module imports neither CasADi nor OpenSim, so the OpenSim bridge's worker process
can import nmsm's plain-Python parts (see :mod:`nmsm.opensim_bridge`).
"""

from __future__ import annotations

from typing import Any

__version__ = "0.1.0"

__all__ = ["__version__", "run", "run_pipeline"]


def run(settings_file: str, **options: Any) -> Any:
    """Run the tool named by the settings file's tool element (as ``nmsm run``)."""
    from nmsm.tools.dispatch import run_settings_file

    return run_settings_file(settings_file, **options)


def run_pipeline(pipeline_file: str, **options: Any) -> Any:
    """Run a chained pipeline file (as ``nmsm pipeline``)."""
    from nmsm.tools.pipeline.runner import run_pipeline_file

    return run_pipeline_file(pipeline_file, **options)

"""nmsm: the Neuromusculoskeletal Modeling Pipeline in Python.

Personalize an OpenSim model (joints, muscle-tendon properties, neural control, foot
contact) from one patient's lab data, then predict and optimize treatment by direct
collocation. Derivatives come from CasADi automatic differentiation.

This module imports neither CasADi nor OpenSim, so the OpenSim bridge's worker process
can import nmsm's plain-Python parts (see :mod:`nmsm.opensim_bridge`).
"""

from __future__ import annotations

import os
from typing import Any

__version__ = "0.1.0"

__all__ = ["__version__", "run", "run_pipeline"]


def _path(value: Any, what: str) -> str | os.PathLike[str]:
    """``value`` if it is a path, else a TypeError naming the argument ``what``."""
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{what}: expected the path of a file (str or os.PathLike), got {type(value).__name__} "
                        f"{value!r}")
    return value


def run(settings_file: str | os.PathLike[str], **options: Any) -> Any:
    """Run the tool named by the settings file's tool element (as ``nmsm run``)."""
    from nmsm.tools.dispatch import run_settings_file

    if options.get("results_directory") is not None:
        _path(options["results_directory"], "nmsm.run(results_directory=...)")
    return run_settings_file(_path(settings_file, "nmsm.run(settings_file)"), **options)


def run_pipeline(pipeline_file: str | os.PathLike[str], **options: Any) -> Any:
    """Run a chained pipeline file (as ``nmsm pipeline``)."""
    from nmsm.tools.pipeline.runner import run_pipeline_file

    return run_pipeline_file(_path(pipeline_file, "nmsm.run_pipeline(pipeline_file)"), **options)

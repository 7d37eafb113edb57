"""nmsm: the Neuromusculoskeletal Modeling Pipeline in Python.

Personalize an OpenSim model (joints, muscle-tendon properties, neural control, foot
contact) from one patient's lab data, then predict and optimize treatment by direct
collocation. Derivatives come from CasADi automatic differentiation.

"The original" in nmsm's comments is the MATLAB NMSM Pipeline: its source is
https://github.com/rcnl-org/nmsm-core, its description the NMSM Pipeline paper
(J. NeuroEngineering Rehabil. 2025, https://doi.org/10.1186/s12984-025-01629-5);
``docs/`` (docs/architecture.md first) says what nmsm's code does.

This module imports neither CasADi nor OpenSim, so the OpenSim bridge's worker process
can import nmsm's plain-Python parts (see :mod:`nmsm.opensim_bridge`).
"""

from __future__ import annotations

import os
from typing import Any

from nmsm.version import __version__

__all__ = ["__version__", "run", "run_pipeline"]


def _path(value: Any, what: str) -> str | os.PathLike[str]:
    """``value`` if it is a path, else a TypeError naming the argument ``what``."""
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{what}: expected the path of a file (str or os.PathLike), got {type(value).__name__} "
                        f"{value!r}")
    return value


def run(settings_file: str | os.PathLike[str], *, plots: bool = False, **options: Any) -> Any:
    """Run the tool named by the settings file's tool element (as ``nmsm run``); ``options``
    are the tool's own. ``plots=True`` then draws the figures of the results folder (and of
    each results folder below it) into its ``plots/``, as ``nmsm plot RESULTS`` does; a
    folder whose figures fail raises :class:`~nmsm.errors.NmsmError` after the others are drawn."""
    from nmsm.tools.dispatch import run_settings_file

    if options.get("results_directory") is not None:
        _path(options["results_directory"], "nmsm.run(results_directory=...)")
    outcome = run_settings_file(_path(settings_file, "nmsm.run(settings_file)"), **options)
    if plots:
        _draw_figures(outcome)
    return outcome


def _draw_figures(outcome: Any) -> None:
    """The figures of the results folder a tool's run returned (its ``results_directory``, or
    the folder itself)."""
    from pathlib import Path

    from nmsm.errors import NmsmError
    from nmsm.plots.cli import plot_tree

    where = outcome if isinstance(outcome, Path) else getattr(outcome, "results_directory", None)
    if where is None:
        raise NmsmError(f"plots=True: the run returned no results folder to draw ({type(outcome).__name__})")
    _, errors = plot_tree(where, log=lambda text: None)
    if errors:
        raise NmsmError("no figures for " + "; ".join(f"{folder}: {message}" for folder, message in errors.items()))


def run_pipeline(pipeline_file: str | os.PathLike[str], **options: Any) -> Any:
    """Run a chained pipeline file (as ``nmsm pipeline``)."""
    from nmsm.tools.pipeline.runner import run_pipeline_file

    return run_pipeline_file(_path(pipeline_file, "nmsm.run_pipeline(pipeline_file)"), **options)

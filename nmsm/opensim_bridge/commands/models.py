"""Loading, checking and re-saving models in OpenSim."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import opensim as osim

from nmsm.opensim_bridge.commands import command

_MODELS: dict[tuple[str, float], Any] = {}


def load_model(path: str) -> Any:
    """An initialized OpenSim model, loaded once per (path, modification time).

    Returns the cached ``osim.Model``; ``initSystem`` has been called. Callers that
    change the state must use their own ``State`` from ``model.initSystem()`` or
    ``model.getWorkingState()``.
    """
    key = (str(Path(path).resolve()), os.path.getmtime(path))
    model = _MODELS.get(key)
    if model is None:
        model = osim.Model(str(path))
        model.initSystem()
        _MODELS[key] = model
    return model


@command
def opensim_version() -> str:
    return osim.GetVersionAndDate()


@command
def model_info(path: str) -> dict[str, Any]:
    """Names and counts of a model's parts, as OpenSim sees them."""
    model = load_model(path)
    cs = model.getCoordinateSet()
    muscles = model.getMuscles()
    return {
        "name": model.getName(),
        "coordinates": [cs.get(i).getName() for i in range(cs.getSize())],
        "bodies": [model.getBodySet().get(i).getName() for i in range(model.getBodySet().getSize())],
        "markers": [model.getMarkerSet().get(i).getName() for i in range(model.getMarkerSet().getSize())],
        "muscles": [muscles.get(i).getName() for i in range(muscles.getSize())],
        "mass": model.getTotalMass(model.getWorkingState()),
        "num_q": model.getNumCoordinates(),
    }


@command
def resave_model(path: str, output: str) -> str:
    """Load ``path`` in OpenSim and print it to ``output`` in the current file format.

    Used to upgrade old model files (versions 20303, 30000) once.
    """
    model = osim.Model(str(path))
    model.initSystem()
    model.printToXML(str(output))
    return str(output)

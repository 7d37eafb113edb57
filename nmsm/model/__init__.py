"""The OpenSim model in nmsm: read from ``.osim`` with lxml and built as CasADi functions.

``load_model(path) -> Model`` (plain data, no CasADi) and ``CasadiModel(model, parameters)``
(CasADi functions: kinematics, inverse dynamics, ...). ``CasadiModel`` and
``ModelParameters`` are imported lazily so that importing this package does not load CasADi.
"""

from __future__ import annotations

from typing import Any

from nmsm.model.components import Model
from nmsm.model.osim import load_model

__all__ = ["CasadiModel", "Model", "ModelParameters", "load_model"]


def __getattr__(name: str) -> Any:
    if name == "CasadiModel":
        from nmsm.model.casadi_model import CasadiModel

        return CasadiModel
    if name == "ModelParameters":
        from nmsm.model.parameters import ModelParameters

        return ModelParameters
    raise AttributeError(f"module 'nmsm.model' has no attribute '{name}'")

"""The OpenSim model in nmsm: read from ``.osim`` with lxml and built as CasADi functions.

``load_model(path) -> Model`` (plain data, no CasADi), ``CasadiModel(model, parameters)``
(CasADi functions: kinematics, inverse dynamics, ...), ``ModelParameters`` (symbolic
joint frames, marker locations, body scales) and ``OsimWriter`` (write changes back into
the file). The last three are imported lazily, so importing this package loads no CasADi.
"""

from __future__ import annotations

from typing import Any

from nmsm.model.components import Model
from nmsm.model.osim import load_model

__all__ = ["CasadiModel", "Model", "ModelParameters", "OsimWriter", "load_model"]


def __getattr__(name: str) -> Any:
    if name == "CasadiModel":
        from nmsm.model.casadi_model import CasadiModel

        return CasadiModel
    if name == "ModelParameters":
        from nmsm.model.parameters import ModelParameters

        return ModelParameters
    if name == "OsimWriter":
        from nmsm.model.osim_writer import OsimWriter

        return OsimWriter
    raise AttributeError(f"module 'nmsm.model' has no attribute '{name}'")

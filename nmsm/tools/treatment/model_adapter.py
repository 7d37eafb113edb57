"""nmsm's OpenSim model (``nmsm.model``) as a :class:`TreatmentModel`.

Inverse dynamics is OpenSim's ID tool's: all muscles disabled, gravity on, no external
loads except those of the problem's contact models (``load_bodies``). Speeds are OpenSim
generalized speeds (coordinate rates for the joints the tutorials use).

With :class:`~nmsm.model.parameters.ModelParameters` (Design Optimization's joint-frame
model functions, :mod:`nmsm.modifiers.joint_frame`) every function below takes the model
parameters ``p`` (``parameter_count``,) as its last input.
"""

from __future__ import annotations

import os
from functools import cached_property

import casadi as cs

from nmsm.core.function_names import function_name
from nmsm.model import CasadiModel, Model, load_model
from nmsm.model.parameters import ModelParameters


class OsimTreatmentModel:
    """Adapter: per-point CasADi functions of an ``.osim`` model (``parameters``: see the
    module docstring)."""

    def __init__(self, model: Model | str | os.PathLike[str], parameters: ModelParameters | None = None) -> None:
        self.model = model if isinstance(model, Model) else load_model(model)
        self.casadi = CasadiModel(self.model, parameters)
        self._rotational = {c.name: c.is_rotational for c in self.model.coordinates}

    @property
    def parameters(self) -> ModelParameters:
        return self.casadi.parameters

    @property
    def parameter_count(self) -> int:
        """Number of model parameters (0 for the file's model)."""
        return int(self.casadi.parameters.size)

    def _parameter_inputs(self) -> list[cs.SX]:
        return [self.casadi.p] if self.casadi.has_parameters else []

    @property
    def file(self) -> str:
        return self.model.file

    @cached_property
    def coordinate_names(self) -> tuple[str, ...]:
        return tuple(self.model.coordinate_names)

    @cached_property
    def independent_coordinates(self) -> tuple[str, ...]:
        return tuple(self.casadi.coordinates.independent_names)

    @cached_property
    def marker_names(self) -> tuple[str, ...]:
        return tuple(self.model.marker_names)

    @cached_property
    def body_names(self) -> tuple[str, ...]:
        return tuple(self.model.body_names)

    def is_rotational(self, coordinate: str) -> bool:
        return self._rotational[coordinate]

    def coordinate_joint(self, coordinate: str) -> str:
        return self.model.coordinate(coordinate).joint

    def load_label(self, coordinate: str) -> str:
        return f"{coordinate}_moment" if self._rotational[coordinate] else f"{coordinate}_force"

    def expand_function(self) -> cs.Function:
        return self.casadi.coordinates.expand

    def inverse_dynamics_function(self, load_bodies: tuple[str, ...] = ()) -> cs.Function:
        """``(q, qd, qdd[, loads 9 x k]) -> tau``; ``loads`` (force, point, torque in ground)
        act on ``load_bodies`` (contact models)."""
        return self.casadi.inverse_dynamics_function(tuple(load_bodies))

    def marker_function(self, marker: str) -> cs.Function:
        return self.casadi.marker_function([marker])

    def body_rotation_function(self, body: str) -> cs.Function:
        pose = self.casadi.body_pose_function(body)
        inputs = [cs.SX.sym("q", len(self.coordinate_names)), *self._parameter_inputs()]
        return cs.Function(function_name("rotation", body), inputs, [pose(*inputs)[0]])

    def body_origin_function(self, body: str) -> cs.Function:
        pose = self.casadi.body_pose_function(body)
        inputs = [cs.SX.sym("q", len(self.coordinate_names)), *self._parameter_inputs()]
        return cs.Function(function_name("origin", body), inputs, [pose(*inputs)[1]])

"""nmsm's OpenSim model (``nmsm.model``) as a :class:`TreatmentModel`.

Inverse dynamics is OpenSim's ID tool's: all muscles disabled, gravity on, no external
loads except those of the problem's contact models (``load_bodies``). Speeds are OpenSim
generalized speeds (coordinate rates for the joints the tutorials use).
"""

from __future__ import annotations

import os
from functools import cached_property

import casadi as cs

from nmsm.model import CasadiModel, Model, load_model


class OsimTreatmentModel:
    """Adapter: per-point CasADi functions of an ``.osim`` model."""

    def __init__(self, model: Model | str | os.PathLike[str]) -> None:
        self.model = model if isinstance(model, Model) else load_model(model)
        self.casadi = CasadiModel(self.model)
        self._rotational = {c.name: c.is_rotational for c in self.model.coordinates}

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
        q = cs.SX.sym("q", len(self.coordinate_names))
        return cs.Function(f"rotation_{body}", [q], [pose(q)[0]])

    def body_origin_function(self, body: str) -> cs.Function:
        pose = self.casadi.body_pose_function(body)
        q = cs.SX.sym("q", len(self.coordinate_names))
        return cs.Function(f"origin_{body}", [q], [pose(q)[1]])

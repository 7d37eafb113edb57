"""GCP's elastic-foundation foot contact (docs/gcp.md) as a Treatment Optimization contact model.

One instance per ``RCNLContactSurface`` of the ``.osimx`` (springs on the hindfoot and toes
bodies, from Ground Contact Personalization). Loads go to the hindfoot and toes bodies; the
ground reaction is reported about the midfoot-superior marker projected on the floor (its
point written with y = resting spring length, as the original). Parameters (modifiable by
model functions, e.g. ``applyBeltSpeedParameter``): damping factor, dynamic and viscous friction,
resting spring length, latching velocity, belt speed (m/s). Formulas:
:mod:`nmsm.model.foot_contact`.
"""

from __future__ import annotations

from typing import Any, ClassVar

import casadi as cs
import numpy as np

from nmsm.core.function_names import function_name
from nmsm.core.plugin_bases import ContactModel
from nmsm.errors import InputError, ModelError
from nmsm.model.foot_contact import CONTACT_PARAMETERS, ContactSurfaceModel, contact_function


class ElasticFoundationContact(ContactModel):
    """Spring-grid foot contact of an ``.osimx`` contact surface."""

    type: ClassVar[str] = "elastic_foundation"
    moment_about_floor_point: ClassVar[bool] = True
    follows_model_parameters: ClassVar[bool] = True

    def __init__(self, surface: Any, model: Any, index: int) -> None:
        self.surface = ContactSurfaceModel.from_osimx(surface, model)
        self.name = f"surface_{index + 1}"
        self.is_left_foot = bool(surface.is_left_foot)
        self.load_bodies = self.surface.bodies
        self.force_labels = tuple(surface.force_columns)
        self.moment_labels = tuple(surface.moment_columns)
        self.point_labels = tuple(surface.electrical_center_columns)
        self.values: list[Any] = list(self.surface.parameters.vector())
        #: (1, n_m) values of the model's joint-frame parameters (DO model functions), or None
        self.model_parameter_row: Any = None

    @property
    def hindfoot_body(self) -> str | None:
        return self.surface.hindfoot_body

    @classmethod
    def discover(cls, setup: Any) -> list[ContactModel]:
        if setup.osimx is None or getattr(setup.model, "model", None) is None:
            return []
        from nmsm.io.osimx import check_contact_surfaces, read_osimx

        osimx = read_osimx(setup.osimx)
        check_contact_surfaces(osimx)
        contacts = []
        for i, surface in enumerate(osimx.contact_surfaces):
            try:
                contacts.append(cls(surface, setup.model.model, i))
            except ModelError as exc:  # a body name of the .osimx the model lacks: name the .osimx, not the model
                raise InputError(f"contact surface {i + 1}: {exc.detail} (model {exc.file})", file=osimx.source,
                                 line=surface.line, element=exc.element, expected=exc.expected) from None
        return contacts

    def belt_speed(self) -> Any:
        return self.values[CONTACT_PARAMETERS.index("belt_speed")]

    def set_belt_speed(self, value: Any) -> None:
        self.set_parameter("belt_speed", value)

    def set_parameter(self, name: str, value: Any) -> None:
        """Replace one of ``CONTACT_PARAMETERS`` (e.g. ``belt_speed``) by a value or MX."""
        self.values[CONTACT_PARAMETERS.index(name)] = value

    def bind_model_parameters(self, row: Any) -> None:
        """Follow a parametric model: ``row`` (1, n_m) are its parameters' values (MX); they are
        appended to :meth:`parameters` and the point function's ``p``."""
        self.model_parameter_row = row

    def parameters(self) -> Any:
        row = cs.horzcat(*[cs.MX(v) for v in self.values])
        return row if self.model_parameter_row is None else cs.horzcat(row, self.model_parameter_row)

    def point_function(self, model: Any) -> cs.Function:
        """``(q, qd, p) -> (loads 9 x k, force, moment, point)``; ``p`` = the contact parameters
        (``CONTACT_PARAMETERS``) followed, for a parametric model, by the model's parameters."""
        cm = model.casadi
        surface = self.surface
        q, qd = cs.SX.sym("q", cm.n), cs.SX.sym("qd", cm.n)
        p = cs.SX.sym("p", len(CONTACT_PARAMETERS))
        geometry = [cm.p] if cm.has_parameters else []  # the model's parameters, when it has any
        positions, velocities = surface.spring_kinematics(cm, q, qd, *geometry)
        marker = cm.marker_function([surface.midfoot_superior_marker])(q, *geometry)
        reference = cs.vertcat(marker[0], 0, marker[2])
        force, moment, forces = contact_function(surface.n_springs)(positions, velocities,
                                                                    cs.DM(surface.spring_constants), p, reference)
        columns = []
        for body in surface.bodies:
            _, origin = cm.body_pose_function(body)(q, *geometry)
            total, torque = cs.SX.zeros(3, 1), cs.SX.zeros(3, 1)
            for j, spring_body in enumerate(surface.spring_bodies):
                if spring_body == body:
                    total = total + forces[:, j]
                    torque = torque + cs.cross(positions[:, j] - origin, forces[:, j])
            columns.append(cs.vertcat(total, origin, torque))
        point = cs.vertcat(marker[0], p[CONTACT_PARAMETERS.index("resting_spring_length")], marker[2])
        inputs = cs.vertcat(p, *geometry)
        return cs.Function(function_name("contact", self.name), [q, qd, inputs], [cs.horzcat(*columns), force, moment, point])

    def spring_count(self) -> int:
        return int(np.size(self.surface.spring_constants))

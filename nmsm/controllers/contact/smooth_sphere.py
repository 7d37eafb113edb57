"""OpenSim's SmoothSphereHalfSpaceForce elements of the model as a contact model.

One instance per force-applying ``SmoothSphereHalfSpaceForce`` of the ``.osim`` (e.g. the
2D gait model of the Moco example). The force acts on the sphere's body at the contact
point; the ground reaction columns are ``<name>_force_vx|vy|vz``, ``<name>_torque_x|y|z``
(about the ground origin) and ``<name>_force_px|py|pz`` (contact point). Formulas:
:mod:`nmsm.model.contact_smooth_sphere`.
"""

from __future__ import annotations

from typing import Any, ClassVar

import casadi as cs

from nmsm.core.plugin_bases import ContactModel


class SmoothSphereContact(ContactModel):
    """A SmoothSphereHalfSpaceForce of the model (no parameters)."""

    type: ClassVar[str] = "smooth_sphere_half_space"

    def __init__(self, model: Any, index: int) -> None:
        element = [f for f in model.model.contact_forces if f.applies_force][index]
        self.index = index
        self.name = element.name
        self.load_bodies = (model.model.contact_geometry[element.sphere].body,)
        self.force_labels = tuple(f"{self.name}_force_v{a}" for a in "xyz")
        self.moment_labels = tuple(f"{self.name}_torque_{a}" for a in "xyz")
        self.point_labels = tuple(f"{self.name}_force_p{a}" for a in "xyz")

    @classmethod
    def discover(cls, setup: Any) -> list[ContactModel]:
        model = setup.model
        osim = getattr(model, "model", None)
        if osim is None:
            return []
        n = len([f for f in osim.contact_forces if f.applies_force])
        return [cls(model, i) for i in range(n)]

    def point_function(self, model: Any) -> cs.Function:
        cm = model.casadi
        q, qd, p = cs.SX.sym("q", cm.n), cs.SX.sym("qd", cm.n), cs.SX.sym("p", 0)
        forces, points = cm.contact_force_function()(q, qd)
        force, point = forces[:, self.index], points[:, self.index]
        loads = cs.vertcat(force, point, cs.SX.zeros(3, 1))
        return cs.Function(f"contact_{self.name}", [q, qd, p], [loads, force, cs.cross(point, force), point])

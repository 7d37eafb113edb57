"""OpenSim's SmoothSphereHalfSpaceForce elements of the model as contact models.

Formulas (as Simbody/OpenSim compute them, checked against OpenSim through the bridge in
``tests/model/test_contact.py`` and ``tests/tools/treatment/test_moco2d.py``):
:mod:`nmsm.model.contact_smooth_sphere`.

Two layouts, chosen by :meth:`SmoothSphereContact.discover`:

* **per foot** (OpenSim's gait convention, as ``createExternalLoadsTableForGait`` and
  Moco's ``MocoContactTrackingGoal`` groups use it): when the tracked ground reactions
  (``GRFData/<trial>.sto``) have the columns ``ground_force_r_vx`` / ``ground_force_l_vx``,
  the force elements whose names end in ``_r`` (``_l``) are summed into one contact model
  ``ground_force_r`` (``ground_force_l``) with columns ``ground_force_<s>_vx|vy|vz``,
  ``ground_torque_<s>_x|y|z`` and ``ground_force_<s>_px|py|pz``. The Moco 2D gait reference
  ``referenceGRF.sto`` has these columns.
* **per element** otherwise: one model per force-applying element, columns
  ``<name>_force_vx|vy|vz``, ``<name>_torque_x|y|z`` and ``<name>_force_px|py|pz``.

Each element's force acts on its sphere's body at the contact point (N, m, ground). The
reported point is the contact point (per foot: the normal-force weighted mean of the
contact points) projected on the ground (y = 0), and the torque is the reaction's moment
about that point, so force, point and torque are an equivalent load (as an OpenSim
ExternalForce applies them) and the moment is taken about the same kind of point as the
tracked moment (``ContextQuantities.tracked_reaction``: the modeled point on the tracked
kinematics, on the ground).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, ClassVar

import casadi as cs

from nmsm.core.function_names import function_name
from nmsm.core.plugin_bases import ContactModel

#: sides of OpenSim's gait ground-reaction convention
SIDES = ("r", "l")


def _labels(prefix: str, torque_prefix: str) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    return (tuple(f"{prefix}_v{a}" for a in "xyz"), tuple(f"{torque_prefix}_{a}" for a in "xyz"),
            tuple(f"{prefix}_p{a}" for a in "xyz"))


class SmoothSphereContact(ContactModel):
    """One SmoothSphereHalfSpaceForce, or the sum of several (one foot); no parameters.

    ``indices``: positions of the elements among the model's force-applying
    SmoothSphereHalfSpaceForce elements; ``name``: the model's name (element name, or
    ``ground_force_<side>`` for a foot group).
    """

    type: ClassVar[str] = "smooth_sphere_half_space"

    def __init__(self, model: Any, index: int | Sequence[int], name: str | None = None) -> None:
        elements = [f for f in model.model.contact_forces if f.applies_force]
        self.indices = (index,) if isinstance(index, int) else tuple(index)
        if not self.indices:
            raise ValueError("a smooth sphere contact model needs at least one element")
        chosen = [elements[i] for i in self.indices]
        self.index = self.indices[0]
        self.element_names = tuple(e.name for e in chosen)
        bodies = []
        for e in chosen:
            body = model.model.contact_geometry[e.sphere].body
            if body not in bodies:
                bodies.append(body)
        self.load_bodies = tuple(bodies)
        self._body_of = [bodies.index(model.model.contact_geometry[e.sphere].body) for e in chosen]
        if name is None and len(chosen) == 1:
            self.name = chosen[0].name
            self.force_labels, self.moment_labels, self.point_labels = _labels(f"{self.name}_force",
                                                                               f"{self.name}_torque")
        else:
            self.name = name or "+".join(self.element_names)
            torque = self.name.replace("_force_", "_torque_") if "_force_" in self.name else f"{self.name}_torque"
            self.force_labels, self.moment_labels, self.point_labels = _labels(self.name, torque)

    @classmethod
    def discover(cls, setup: Any) -> list[ContactModel]:
        model = setup.model
        osim = getattr(model, "model", None)
        if osim is None:
            return []
        names = [f.name for f in osim.contact_forces if f.applies_force]
        if not names:
            return []
        groups = cls.foot_groups(names, getattr(setup, "references", {}).get("ground_reactions"))
        if groups:
            return [cls(model, indices, f"ground_force_{side}") for side, indices in groups.items()]
        return [cls(model, i) for i in range(len(names))]

    @staticmethod
    def foot_groups(names: Sequence[str], tracked: Any) -> dict[str, tuple[int, ...]]:
        """{side: element indices} when ``tracked`` (ground-reaction splines or None) has
        OpenSim's gait columns for every side that has elements ending in ``_<side>``,
        and every element belongs to a side; else {}."""
        if tracked is None or not hasattr(tracked, "has"):
            return {}
        groups = {side: tuple(i for i, n in enumerate(names) if n.endswith(f"_{side}")) for side in SIDES}
        groups = {side: idx for side, idx in groups.items() if idx}
        if sum(len(idx) for idx in groups.values()) != len(names):
            return {}
        if not groups or not all(tracked.has(f"ground_force_{side}_vx") for side in groups):
            return {}
        return groups

    def point_function(self, model: Any) -> cs.Function:
        cm = model.casadi
        q, qd, p = cs.SX.sym("q", cm.n), cs.SX.sym("qd", cm.n), cs.SX.sym("p", 0)
        forces, points = cm.contact_force_function()(q, qd)
        loads = cs.SX.zeros(9, len(self.load_bodies))
        total = cs.SX.zeros(3, 1)
        moment = cs.SX.zeros(3, 1)
        weighted = cs.SX.zeros(3, 1)
        weight = cs.SX(0.0)
        for j, index in enumerate(self.indices):
            force, point = forces[:, index], points[:, index]
            column = self._body_of[j]
            # several elements on one body: add the forces and their moments about the ground origin
            torque = cs.cross(point, force)
            loads[0:3, column] = loads[0:3, column] + force
            loads[6:9, column] = loads[6:9, column] + torque
            total = total + force
            moment = moment + torque
            normal = cs.fabs(force[1])
            weighted = weighted + normal * point
            weight = weight + normal
        if len(self.indices) == 1:
            point = points[:, self.indices[0]]
            loads = cs.vertcat(forces[:, self.indices[0]], point, cs.SX.zeros(3, 1))
        else:
            # loads given as (force, point = ground origin, torque about the origin): equivalent
            point = weighted / (weight + 1e-6)
        on_ground = cs.vertcat(point[0], 0, point[2])
        about_point = moment - cs.cross(on_ground, total)
        return cs.Function(function_name("contact", self.name), [q, qd, p], [loads, total, about_point, on_ground])

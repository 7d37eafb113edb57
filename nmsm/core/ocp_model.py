"""What optimal control (Treatment Optimization) needs from a model: per-point CasADi functions.

:class:`TreatmentModel` is the protocol; :mod:`nmsm.tools.treatment.model_adapter` wraps
nmsm's OpenSim model (``nmsm.model``) in it, and tests implement it for small synthetic
models (a pendulum). Every function takes and returns column vectors for ONE time point and
should be built from SX; the treatment context ``map``\\ s them over the grid's points.

Units: SI, radians. ``nq`` = number of model coordinates (all of them, in model order).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import casadi as cs


@runtime_checkable
class TreatmentModel(Protocol):
    """Kinematics and inverse dynamics of a model, as CasADi functions of one point."""

    #: all coordinates, in the order of every ``q``/``tau`` vector below
    coordinate_names: tuple[str, ...]
    #: coordinates not driven by a coupler constraint (the others follow from them)
    independent_coordinates: tuple[str, ...]
    marker_names: tuple[str, ...]
    body_names: tuple[str, ...]

    def is_rotational(self, coordinate: str) -> bool:
        """True for rotational coordinates (rad), False for translational ones (m)."""

    def coordinate_joint(self, coordinate: str) -> str:
        """The name of the joint holding ``coordinate`` (its state paths: ``/jointset/<joint>/<coordinate>/value``)."""

    def load_label(self, coordinate: str) -> str:
        """The inverse-dynamics column label: ``<coordinate>_moment`` or ``<coordinate>_force``."""

    def expand_function(self) -> cs.Function:
        """``(q_ind, qd_ind, qdd_ind) -> (q, qd, qdd)``: independent coordinates (order of
        :attr:`independent_coordinates`) to all coordinates, couplers' chain rule included."""

    def inverse_dynamics_function(self, load_bodies: tuple[str, ...] = ()) -> cs.Function:
        """``(q, qd, qdd[, loads]) -> tau`` (nq,): generalized forces (N·m or N) that produce
        ``qdd`` with gravity and no muscles (OpenSim's inverse dynamics tool); with
        ``load_bodies``, ``loads`` (9, k) are (force N, point m, torque N·m) in ground applied
        on those bodies (contact models; models without contact may ignore the argument)."""

    def marker_function(self, marker: str) -> cs.Function:
        """``q -> p`` (3,): marker position in ground (m)."""

    def body_rotation_function(self, body: str) -> cs.Function:
        """``q -> R`` (3, 3): rotation of ``body`` in ground (columns = body axes)."""

    def body_origin_function(self, body: str) -> cs.Function:
        """``q -> p`` (3,): origin of ``body`` in ground (m)."""

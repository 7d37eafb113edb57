"""Coupled (dependent) coordinates: ``beta = scale * f(q_independent)`` and its rates.

:class:`CoordinateMap` builds SX functions from the independent coordinates (those not
driven by an enforced CoordinateCouplerConstraint, in model order) to the full
coordinate vector (model order), by the chain rule:

    beta      = s f(q)
    beta_dot  = s f'(q) q_dot
    beta_ddot = s f''(q) q_dot^2 + s f'(q) q_ddot
"""

from __future__ import annotations

from typing import Any

import casadi as cs
import numpy as np

from nmsm.model.components import Model
from nmsm.model.functions import value_and_derivatives


class CoordinateMap:
    """Independent-coordinate view of a model's coordinates."""

    def __init__(self, model: Model) -> None:
        self.model = model
        names = model.coordinate_names
        self.names = names
        couplers = model.coupled_coordinates
        self.independent_names = [n for n in names if n not in couplers]
        self.dependent_names = [n for n in names if n in couplers]
        self.independent_indices = [names.index(n) for n in self.independent_names]
        self.dependent_indices = [names.index(n) for n in self.dependent_names]
        self._couplers = couplers
        n_ind = len(self.independent_names)
        q = cs.SX.sym("q_ind", n_ind)
        qd = cs.SX.sym("qdot_ind", n_ind)
        qdd = cs.SX.sym("qddot_ind", n_ind)
        full_q, full_qd, full_qdd = self._expand(q, qd, qdd)
        self.expand_q = cs.Function("expand_q", [q], [full_q], ["q_ind"], ["q"])
        self.expand_qdot = cs.Function("expand_qdot", [q, qd], [full_qd], ["q_ind", "qdot_ind"], ["qdot"])
        self.expand_qddot = cs.Function("expand_qddot", [q, qd, qdd], [full_qdd],
                                        ["q_ind", "qdot_ind", "qddot_ind"], ["qddot"])
        self.expand = cs.Function("expand", [q, qd, qdd], [full_q, full_qd, full_qdd],
                                  ["q_ind", "qdot_ind", "qddot_ind"], ["q", "qdot", "qddot"])

    @property
    def n_independent(self) -> int:
        return len(self.independent_names)

    def _expand(self, q: cs.SX, qd: cs.SX, qdd: cs.SX) -> tuple[cs.SX, cs.SX, cs.SX]:
        n = len(self.names)
        values: list[Any] = [None] * n
        rates: list[Any] = [None] * n
        accelerations: list[Any] = [None] * n
        for k, i in enumerate(self.independent_indices):
            values[i], rates[i], accelerations[i] = q[k], qd[k], qdd[k]
        for name in self.dependent_names:
            coupler = self._couplers[name]
            i = self.names.index(name)
            j = self.names.index(coupler.independent[0])
            value, slope, curvature = (coupler.scale_factor * v
                                       for v in value_and_derivatives(coupler.function, values[j]))
            values[i] = value
            rates[i] = slope * rates[j]
            accelerations[i] = curvature * rates[j] ** 2 + slope * accelerations[j]
        return cs.vertcat(*values), cs.vertcat(*rates), cs.vertcat(*accelerations)

    def independent(self, full: Any) -> Any:
        """The independent entries of a full coordinate vector (numpy: last axis)."""
        if isinstance(full, np.ndarray):
            return full[..., self.independent_indices]
        return cs.vertcat(*[full[i] for i in self.independent_indices])

    def dependent_values(self, q_full: np.ndarray) -> np.ndarray:
        """Full coordinates with the dependent entries recomputed from the independent
        ones (numpy, ``(..., n)``)."""
        q_full = np.array(q_full, dtype=float)
        flat = q_full.reshape(-1, q_full.shape[-1])
        out = np.array(self.expand_q.map(flat.shape[0])(flat[:, self.independent_indices].T)).T
        return out.reshape(q_full.shape)

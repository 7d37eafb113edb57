"""The values GCP optimizes, as numbers (:class:`GcpState`, between tasks) or as the mix
of CasADi design variables and fixed numbers a task sees (:class:`Design`).

Shared by the feet optimized together: spring constants ``K`` (n,) N/m, damping factor D
(s/m), dynamic friction coefficient mu_d, viscous friction coefficient mu_v (s/m), resting
spring length L0 (m) and the fixed latching velocity (m/s). Per foot: the kinematic
B-spline coefficients C (m, 7) (multiplicative, initially 1), the electrical-center shift
(3,) m and the force-plate rotation about ground y (rad).
"""

from __future__ import annotations

from typing import Any

import attrs
import numpy as np

from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.model.foot_contact import stack_parameters
from nmsm.tools.gcp.inputs import FootInputs


@attrs.define
class GcpState:
    """Current numeric values of every optimized quantity (module docstring)."""

    spring_constants: np.ndarray
    damping_factor: float
    dynamic_friction_coefficient: float
    viscous_friction_coefficient: float
    resting_spring_length: float
    latching_velocity: float
    coefficients: list[np.ndarray]
    electrical_center_shifts: list[np.ndarray]
    plate_rotations: list[float]

    @classmethod
    def initial(cls, settings: GroundContactPersonalizationSettings, feet: list[FootInputs]) -> GcpState:
        """Initial values from the settings (every coefficient 1, no shift, no rotation)."""
        n = feet[0].springs.n_springs
        return cls(
            spring_constants=np.full(n, settings.initial_spring_constant),
            damping_factor=settings.initial_damping_factor,
            dynamic_friction_coefficient=settings.initial_dynamic_friction_coefficient,
            viscous_friction_coefficient=settings.initial_viscous_friction_coefficient,
            resting_spring_length=settings.initial_resting_spring_length,
            latching_velocity=settings.latching_velocity,
            coefficients=[np.ones((f.n_nodes, 7)) for f in feet],
            electrical_center_shifts=[np.zeros(3) for _ in feet],
            plate_rotations=[0.0 for _ in feet],
        )

    def copy(self) -> GcpState:
        return GcpState(
            spring_constants=self.spring_constants.copy(),
            damping_factor=self.damping_factor,
            dynamic_friction_coefficient=self.dynamic_friction_coefficient,
            viscous_friction_coefficient=self.viscous_friction_coefficient,
            resting_spring_length=self.resting_spring_length,
            latching_velocity=self.latching_velocity,
            coefficients=[c.copy() for c in self.coefficients],
            electrical_center_shifts=[s.copy() for s in self.electrical_center_shifts],
            plate_rotations=list(self.plate_rotations),
        )

    def design(self) -> Design:
        """The state as a :class:`Design` of numbers (for evaluating modeled values)."""
        import casadi as cs

        return Design(
            spring_constants=cs.DM(self.spring_constants),
            damping_factor=self.damping_factor,
            dynamic_friction_coefficient=self.dynamic_friction_coefficient,
            viscous_friction_coefficient=self.viscous_friction_coefficient,
            resting_spring_length=self.resting_spring_length,
            latching_velocity=self.latching_velocity,
            coefficients=[cs.DM(c) for c in self.coefficients],
            electrical_center_shifts=[cs.DM(s) for s in self.electrical_center_shifts],
            plate_rotations=[cs.DM(r) for r in self.plate_rotations],
        )


@attrs.define
class Design:
    """A task's view of the state: each field a number or a CasADi expression."""

    spring_constants: Any
    damping_factor: Any
    dynamic_friction_coefficient: Any
    viscous_friction_coefficient: Any
    resting_spring_length: Any
    latching_velocity: Any
    coefficients: list[Any]
    electrical_center_shifts: list[Any]
    plate_rotations: list[Any]

    def contact_parameters(self, belt_speed: float) -> Any:
        """(6, 1) contact parameter column for a foot on a belt at ``belt_speed`` m/s."""
        return stack_parameters([self.damping_factor, self.dynamic_friction_coefficient,
                                 self.viscous_friction_coefficient, self.resting_spring_length,
                                 self.latching_velocity, belt_speed])

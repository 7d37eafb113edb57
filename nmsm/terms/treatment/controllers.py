"""Controller costs (docs/terms.md). ``controller`` names a control of the problem's
controllers: a torque-controlled coordinate (``c``, ``c_moment``), a synergy activation
(``<group>_<k>``) or a muscle (individual activation controller).

``controller_tracking``           u - scale·u_init   (u_init: the initial guess's controls)
``controller_minimization``       u
``controller_slope_minimization`` du/dt (per second) of the control's interpolating polynomial
                                  in each mesh interval (the original differentiates a
                                  not-a-knot cubic spline of u); ``normalize_by_final_time``
                                  defaults to false as in the original. Controls may jump
                                  between mesh intervals, which this derivative does not see:
                                  building it gives a DiscontinuousDerivativeWarning
``controller_shape_tracking``     u_init - k·u, k = (u·u_init)/(u·u) (DO)
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs

from nmsm.core.ocp import ContinuousCost


@attrs.frozen(kw_only=True)
class _ControllerCost(ContinuousCost):
    controller: str

    def bind(self, ctx: Any) -> None:
        ctx.require_control(self, self.controller)


@attrs.frozen(kw_only=True)
class ControllerTracking(_ControllerCost):
    """Tracks a control's initial guess: u - scale·u_init (control units)."""

    type: ClassVar[str] = "controller_tracking"
    scale_factor: float = 1.0

    def quantity(self, ctx: Any) -> Any:
        return ctx.control(self.controller) - self.scale_factor * ctx.initial_control(self.controller)


@attrs.frozen(kw_only=True)
class ControllerMinimization(_ControllerCost):
    """Minimizes a control u (control units)."""

    type: ClassVar[str] = "controller_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})

    def quantity(self, ctx: Any) -> Any:
        return ctx.control(self.controller)


@attrs.frozen(kw_only=True)
class ControllerSlopeMinimization(_ControllerCost):
    """Minimizes a control's time derivative du/dt (control units per second)."""

    type: ClassVar[str] = "controller_slope_minimization"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    normalize_by_final_time: bool = False

    def quantity(self, ctx: Any) -> Any:
        return ctx.differentiate(ctx.control(self.controller))


@attrs.frozen(kw_only=True)
class ControllerShapeTracking(_ControllerCost):
    """Tracks a control's shape: u_init - k·u with the least-squares scale k."""

    type: ClassVar[str] = "controller_shape_tracking"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})

    def quantity(self, ctx: Any) -> Any:
        u = ctx.control(self.controller)
        u0 = cs.MX(ctx.initial_control(self.controller))
        k = cs.dot(u, u0) / (cs.dot(u, u) + 1e-12)
        return u0 - k * u

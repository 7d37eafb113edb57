"""Periodicity of what drives the model (not in the original's catalog; added for half gait
cycles as OpenSim Moco's ``MocoPeriodicityGoal`` pairs them):

``muscle_activation_periodicity``  a(t_f) of ``muscle`` - a(t0) of ``pair_muscle`` (default
                                   the same muscle); dimensionless
``controller_periodicity``         u(t_f) of ``controller`` - u(t0) of ``pair_controller``
                                   (default the same control); the control's units

Each is bounded by ``[min_error, max_error]``. A muscle's activation at t_f is its state at
the phase end under activation dynamics (``<RCNLMuscleController>`` with
``activation_dynamics``), else the controls' extrapolation to t_f, as for every control.
"""

from __future__ import annotations

from typing import Any, ClassVar

import attrs

from nmsm.core.ocp import TerminalConstraint


@attrs.frozen(kw_only=True)
class MuscleActivationPeriodicity(TerminalConstraint):
    """a(t_f) of ``muscle`` - a(t0) of ``pair_muscle`` (left/right mapping of half cycles)."""

    type: ClassVar[str] = "muscle_activation_periodicity"
    muscle: str
    pair_muscle: str | None = None

    def bind(self, ctx: Any) -> None:
        ctx.require_muscle(self, self.muscle, element="<muscle>")
        ctx.require_muscle(self, self.pair_muscle or self.muscle, element="<pair_muscle>")

    def value(self, ctx: Any) -> Any:
        return ctx.final.muscle_activation(self.muscle) - ctx.initial.muscle_activation(self.pair_muscle or self.muscle)


@attrs.frozen(kw_only=True)
class ControllerPeriodicity(TerminalConstraint):
    """u(t_f) of ``controller`` - u(t0) of ``pair_controller`` (a control by the name used in
    ``<controller_list>``, e.g. a torque-controlled coordinate or a muscle's excitation)."""

    type: ClassVar[str] = "controller_periodicity"
    controller: str
    pair_controller: str | None = None

    def bind(self, ctx: Any) -> None:
        ctx.require_control(self, self.controller, element="<controller>")
        ctx.require_control(self, self.pair_controller or self.controller, element="<pair_controller>")

    def value(self, ctx: Any) -> Any:
        return ctx.final.control(self.controller) - ctx.initial.control(self.pair_controller or self.controller)

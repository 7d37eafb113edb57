"""Contracts of optimal-control terms (Treatment Optimization: TO, VO, DO).

A term subclasses one of four bases and declares, through the base, how the tool evaluates
it (:attr:`OcpTerm.evaluation`); the tool reads that declaration, never the term's class:

``ContinuousCost``     ``evaluation = "continuous"``: ``quantity(ctx)`` -> (K, 1) on the
                       collocation points; the objective gets ``integral_0^1 ((g - c)/e)^2 ds``
                       over normalized time ``s`` (a time average; times ``t_f`` when
                       ``normalize_by_final_time`` is false), restricted to ``time_ranges``.
``DiscreteCost``       ``evaluation = "discrete"``: ``quantity(ctx)`` -> scalar; the objective
                       gets ``((v - c)/e)^2``.
``PathConstraint``     ``evaluation = "path"``: ``value(ctx)`` -> (K, 1);
                       ``min_error <= g(t_k) <= max_error`` at the collocation points (within
                       ``time_ranges`` if given).
``TerminalConstraint`` ``evaluation = "terminal"``: ``value(ctx)`` -> scalar (use
                       ``ctx.initial`` / ``ctx.final``); ``min_error <= v <= max_error``.

``ctx`` is the tool's implementation of :class:`OcpContext`: every quantity a term may ask
for, with units and shapes. Example (a complete continuous cost term)::

    import attrs
    from typing import ClassVar
    from nmsm.core.ocp import ContinuousCost, OcpContext

    @attrs.frozen(kw_only=True)
    class GeneralizedSpeedMinimization(ContinuousCost):
        \"\"\"Minimizes one coordinate's speed (rad/s or m/s).\"\"\"

        type: ClassVar[str] = "generalized_speed_minimization"
        tools: ClassVar[frozenset[str]] = frozenset({"TO", "VO", "DO"})
        coordinate: str

        def bind(self, ctx: OcpContext) -> None:
            ctx.require_coordinate(self, self.coordinate)

        def quantity(self, ctx: OcpContext):
            return ctx.speed(self.coordinate)

The objective is the mean over continuous terms of their integrals plus the mean over
discrete terms (``normalize_cost_by_term_type``: averaged per type first); the tool sets
each term's weight accordingly. Check a term with :func:`nmsm.testing.check_term`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar, Literal, Protocol

import attrs

from nmsm.core.term import ConstraintTerm, CostTerm, TermValueError

#: The tool codes of Treatment Optimization.
TREATMENT_TOOLS = frozenset({"TO", "VO", "DO"})

#: How a tool evaluates a term: on the collocation points (continuous cost, path constraint)
#: or once per solution (discrete cost, terminal constraint).
Evaluation = Literal["continuous", "discrete", "path", "terminal"]

#: Evaluations whose quantity is one (K, 1) column on the collocation points.
ON_COLLOCATION_POINTS: frozenset[str] = frozenset({"continuous", "path"})


def _ranges(instance: Any, attribute: attrs.Attribute, value: tuple[float, ...] | None) -> None:
    expected = "pairs 'start end' of normalized time with 0 <= start < end <= 1"
    if value is None:
        return
    if len(value) % 2 or not value:
        raise TermValueError(f"'{attribute.name}' needs pairs 'start end' in normalized time [0, 1], got {value}",
                             field=attribute.name, expected=expected)
    for a, b in zip(value[::2], value[1::2]):
        if not (0.0 <= a < b <= 1.0):
            raise TermValueError(f"'{attribute.name}': each range must satisfy 0 <= start < end <= 1, got {a} {b}",
                                 field=attribute.name, expected=expected)


class DiscontinuousDerivativeWarning(UserWarning):
    """A term differentiates (``ctx.differentiate``) a quantity that depends on the controls
    (accelerations, torque controls, activations): values at the collocation points free to
    jump from one mesh interval to the next. The derivative is taken inside each interval and
    does not see those jumps, so minimising or bounding it can leave (or create) large jumps
    while the solver reports success. Differentiate states (coordinates, speeds) instead, or
    accept the derivative knowing this. Issued once per term (type, settings file and line)."""


class OcpTerm(Protocol):
    """What every optimal-control term declares to the tool."""

    #: how the tool evaluates the term (see the module docstring)
    evaluation: Evaluation


@attrs.frozen(kw_only=True)
class ContinuousCost(CostTerm):
    """A cost integrated over the movement: ``quantity(ctx)`` -> (K, 1)."""

    evaluation: ClassVar[Evaluation] = "continuous"
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS

    #: normalized-time ranges "a b [c d ...]" where the integrand counts (elsewhere 0)
    time_ranges: tuple[float, ...] | None = attrs.field(default=None, validator=_ranges)
    #: true: time average (integral over normalized time); false: integral over time (s)
    normalize_by_final_time: bool = True


@attrs.frozen(kw_only=True)
class DiscreteCost(CostTerm):
    """A cost evaluated once per solution: ``quantity(ctx)`` -> scalar."""

    evaluation: ClassVar[Evaluation] = "discrete"
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS


@attrs.frozen(kw_only=True)
class PathConstraint(ConstraintTerm):
    """A constraint enforced at every collocation point: ``value(ctx)`` -> (K, 1)."""

    evaluation: ClassVar[Evaluation] = "path"
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS

    time_ranges: tuple[float, ...] | None = attrs.field(default=None, validator=_ranges)


@attrs.frozen(kw_only=True)
class TerminalConstraint(ConstraintTerm):
    """A constraint on values at the start and/or end of the movement: ``value(ctx)`` -> scalar."""

    evaluation: ClassVar[Evaluation] = "terminal"
    tools: ClassVar[frozenset[str]] = TREATMENT_TOOLS


#: The four bases a treatment term subclasses.
OCP_BASES: tuple[type, ...] = (ContinuousCost, DiscreteCost, PathConstraint, TerminalConstraint)


def require_axis(term: Any, axis: str | None) -> int:
    """Index 0/1/2 of ``axis`` ('x', 'y', 'z'), or an InputError naming the term."""
    if axis not in ("x", "y", "z"):
        raise term.error(f"axis '{axis}' is not one of x, y, z", element="<axes>", expected="x, y and/or z")
    return "xyz".index(axis)


class OcpGrid(Protocol):
    """Quantities on one grid of the phase, as CasADi expressions (``n`` rows: the K
    collocation points, or one row for ``ctx.initial`` / ``ctx.final``). SI units, radians.

    A coordinate ``c`` is any model coordinate (state, prescribed or coupler-dependent);
    ``load`` is ``<coordinate>_moment``, ``<coordinate>_force`` or the coordinate's name;
    ``tracked_*`` are the experimental references on the same rows. Unknown names raise
    ``KeyError``; call the matching ``ctx.require_*`` in ``bind`` so a settings mistake is an
    :class:`~nmsm.errors.InputError` before any solve.
    """

    @property
    def n(self) -> int:
        """Rows of the grid."""

    @property
    def normalized_time(self) -> Any:
        """(n,) normalized time ``s`` in [0, 1] (numpy)."""

    def time(self) -> Any:
        """(n, 1) time (s): ``t_f * s``."""

    def positions(self) -> Any:
        """(n, nq) every coordinate (rad or m), model order."""

    def speeds(self) -> Any:
        """(n, nq) every coordinate's speed (rad/s or m/s), model order."""

    def accelerations(self) -> Any:
        """(n, nq) every coordinate's acceleration (rad/s² or m/s²), model order."""

    def coordinate(self, name: str) -> Any:
        """(n, 1) q of coordinate ``name`` (rad or m)."""

    def speed(self, name: str) -> Any:
        """(n, 1) q̇ (rad/s or m/s)."""

    def acceleration(self, name: str) -> Any:
        """(n, 1) q̈ (rad/s² or m/s²)."""

    def tracked_coordinate(self, name: str) -> Any:
        """(n, 1) tracked q (rad or m): the IK reference spline."""

    def tracked_speed(self, name: str) -> Any:
        """(n, 1) tracked q̇ (rad/s or m/s)."""

    def tracked_acceleration(self, name: str) -> Any:
        """(n, 1) tracked q̈ (rad/s² or m/s²)."""

    def inverse_dynamics(self) -> Any:
        """(n, nq) inverse-dynamics loads of the modeled motion (N·m or N), model order."""

    def inverse_dynamics_load(self, load: str) -> Any:
        """(n, 1) inverse-dynamics load ``load`` of the modeled motion (N·m or N)."""

    def tracked_load(self, load: str) -> Any:
        """(n, 1) experimental inverse-dynamics load (N·m or N)."""

    def controller_load(self, load: str) -> Any:
        """(n, 1) what the controllers apply on the load's coordinate (muscle moments plus
        torque controls; N·m or N)."""

    def marker_position(self, marker: str) -> Any:
        """(n, 3) model marker position in ground (m)."""

    def marker_velocity(self, marker: str) -> Any:
        """(n, 3) model marker velocity in ground (m/s)."""

    def tracked_marker_position(self, marker: str) -> Any:
        """(n, 3) the marker on the tracked kinematics (m)."""

    def tracked_marker_velocity(self, marker: str) -> Any:
        """(n, 3) the marker's velocity on the tracked kinematics (m/s)."""

    def body_orientation(self, body: str, sequence: str = "xyz") -> Any:
        """(n, 3) body-fixed angles of ``body`` in ``sequence`` order (rad)."""

    def tracked_body_orientation(self, body: str, sequence: str = "xyz") -> Any:
        """(n, 3) the same angles on the tracked kinematics (rad)."""

    def ground_reaction_force(self, label: str) -> Any:
        """(n, 1) modeled ground reaction force component named by its GRF column (N)."""

    def ground_reaction_moment(self, label: str) -> Any:
        """(n, 1) modeled ground reaction moment component named by its GRF column (N·m)."""

    def tracked_ground_reaction_force(self, label: str) -> Any:
        """(n, 1) experimental ground reaction force column (N)."""

    def tracked_ground_reaction_moment(self, label: str) -> Any:
        """(n, 1) experimental ground reaction moment column (N·m)."""

    def control(self, name: str) -> Any:
        """(n, 1) a controller's control: torque (N·m or N), synergy or muscle activation."""

    def initial_control(self, name: str) -> Any:
        """(n, 1) the control's initial-guess reference."""

    def muscle_activation(self, muscle: str) -> Any:
        """(n, 1) modeled activation of ``muscle`` (0..1)."""

    def tracked_muscle_activation(self, muscle: str) -> Any:
        """(n, 1) reference activation (from the initial-guess directory, 0..1)."""

    def normalized_fiber_length(self, muscle: str) -> Any:
        """(n, 1) normalized fiber length of the Hill model (dimensionless)."""

    def center_of_mass_position(self) -> Any:
        """(n, 3) whole-body centre of mass in ground (m)."""

    def center_of_mass_velocity(self) -> Any:
        """(n, 3) its velocity in ground (m/s)."""

    def angular_momentum(self) -> Any:
        """(n, 3) whole-body angular momentum about the centre of mass, in ground (kg·m²/s)."""

    def center_of_pressure(self, hindfoot_body: str) -> Any:
        """(n, 3) modeled centre of pressure of a foot on the floor (m; y = 0)."""

    def tracked_center_of_pressure(self, hindfoot_body: str) -> Any:
        """(n, 3) experimental centre of pressure of the foot (m; y = 0)."""

    def metabolic_rate(self) -> Any:
        """(n, 1) whole-body metabolic rate (W) of the problem's metabolic model."""

    def cached(self, key: str, compute: Callable[[Any], Any]) -> Any:
        """``compute(grid)`` once per grid and ``key`` (for a term's own derived quantity)."""


class OcpContext(OcpGrid, Protocol):
    """What a Treatment Optimization term receives: the collocation-point grid (K rows) plus
    the phase's end points and problem-wide quantities. Implemented by the treatment tool
    (``nmsm.tools.treatment.context.TreatmentContext``); a term depends on this protocol only.
    """

    tool: str

    @property
    def initial(self) -> OcpGrid:
        """The phase's first point (one row): for terminal constraints."""

    @property
    def final(self) -> OcpGrid:
        """The phase's last point (one row): for terminal constraints."""

    @property
    def final_time(self) -> Any:
        """Duration of the phase (MX scalar, s)."""

    @property
    def state_coordinates(self) -> tuple[str, ...]:
        """Coordinates integrated as states (``<states_coordinate_list>``)."""

    @property
    def controller_names(self) -> tuple[str, ...]:
        """Every control of the problem's controllers."""

    @property
    def muscle_names(self) -> tuple[str, ...]:
        """Muscles of the problem's muscle or synergy controllers."""

    def is_actuated(self, coordinate: str) -> bool:
        """True if a controller applies a load on ``coordinate``."""

    def parameter(self, name: str) -> Any:
        """MX column of a DO static parameter (units of the parameter)."""

    def synergy_weights(self, group: str | None = None) -> Any:
        """(S, M) synergy weights of ``group`` (MX; all groups when None)."""

    def initial_synergy_weights(self, group: str | None = None) -> Any:
        """(S, M) initial synergy weights (numpy)."""

    def integrate(self, values: Any) -> Any:
        """``integral_0^1 values ds`` over normalized time of (K, m) values -> (1, m)."""

    def differentiate(self, values: Any) -> Any:
        """(K, m) time derivative (1/s) of (K, m) collocation values, through each mesh
        interval's polynomial on its collocation points.

        Safe to minimise only for quantities continuous across mesh intervals: the states
        (coordinates and speeds of ``<states_coordinate_list>``) and what depends on them
        only (marker positions, orientations). Quantities that depend on the controls -
        accelerations, inverse-dynamics loads, torque controls, activations - may jump from
        one interval to the next, which this derivative does not see: minimising it can raise
        the true derivative while the solver reports success. Such a term gets a
        :class:`DiscontinuousDerivativeWarning` when it is built (once per term).
        """

    # ---- name checks (raise InputError naming the term's settings file and line) ----
    def require_coordinate(self, term: Any, name: str, element: str = "<coordinate_list>") -> None: ...

    def require_state_coordinate(self, term: Any, name: str, element: str = "<coordinate_list>") -> None: ...

    def require_load(self, term: Any, load: str, element: str = "<load_list>") -> None: ...

    def require_tracked_load(self, term: Any, load: str, element: str = "<load_list>") -> None: ...

    def require_marker(self, term: Any, marker: str, element: str = "<marker_list>") -> None: ...

    def require_body(self, term: Any, body: str, element: str = "<body_list>") -> None: ...

    def require_control(self, term: Any, name: str, element: str = "<controller_list>") -> None: ...

    def require_muscle(self, term: Any, muscle: str, element: str = "<muscle_list>") -> None: ...

    def require_tracked_activation(self, term: Any, muscle: str, element: str = "<muscle_list>") -> None: ...

    def require_synergy(self, term: Any, name: str, element: str = "<synergy_list>") -> None: ...

    def require_reaction(self, term: Any, label: str, kind: str, element: str) -> None: ...

    def require_parameter(self, term: Any, name: str, element: str = "<type>") -> None: ...

    def has_tracked_ground_reaction(self, label: str) -> bool: ...


def evaluation_of(term: Any) -> Evaluation:
    """The term's declared :attr:`OcpTerm.evaluation`, or an InputError naming the term when
    it declares none (a treatment term must subclass one of :data:`OCP_BASES`)."""
    evaluation = getattr(term, "evaluation", None)
    if evaluation not in ("continuous", "discrete", "path", "terminal"):
        raise term.error(f"{type(term).__qualname__} declares no evaluation (subclass ContinuousCost, DiscreteCost, "
                         "PathConstraint or TerminalConstraint from nmsm.core.ocp)")
    return evaluation


__all__ = ["ContinuousCost", "DiscontinuousDerivativeWarning", "DiscreteCost", "Evaluation", "OCP_BASES", "ON_COLLOCATION_POINTS", "OcpContext",
           "OcpGrid", "OcpTerm", "PathConstraint", "TREATMENT_TOOLS", "TerminalConstraint", "evaluation_of",
           "require_axis"]

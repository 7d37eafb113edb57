"""Signals shared by the term families: a modeled quantity and its tracked reference.

Each family (``generalized_coordinate``, ``marker_position``, ...) is a :class:`Signal`
that checks the term's names against the context (``bind``) and returns, on any
:class:`~nmsm.core.ocp.OcpGrid`, the modeled column (n, 1) and the tracked
column (n, 1). Cost, path-constraint and terminal-constraint classes of a family are thin
wrappers over it (``*_tracking`` = tracked - modeled, ``*_deviation`` = modeled - tracked,
``*_value`` = modeled, ``*_periodicity`` = final - initial).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import attrs

from nmsm.core.ocp import require_axis


@attrs.frozen
class Signal:
    """A family's quantity: ``bind(ctx, term)``, ``modeled(view, term)``, ``tracked(view, term)``."""

    name: str
    unit: str
    bind: Callable[[Any, Any], None]
    modeled: Callable[[Any, Any], Any]
    tracked: Callable[[Any, Any], Any] | None = None


def _coordinate_bind(ctx: Any, term: Any) -> None:
    ctx.require_coordinate(term, term.coordinate)


def _marker_bind(ctx: Any, term: Any) -> None:
    ctx.require_marker(term, term.marker)
    require_axis(term, term.axis)


def _body_bind(ctx: Any, term: Any) -> None:
    ctx.require_body(term, term.body)
    require_axis(term, term.axis)


def _orientation_column(angles: Any, term: Any) -> Any:
    seq = (getattr(term, "sequence", None) or "xyz").lower()
    return angles[:, seq.index(term.axis)]


def _load_bind(ctx: Any, term: Any) -> None:
    ctx.require_load(term, term.load)


def _reaction_bind(kind: str) -> Callable[[Any, Any], None]:
    def bind(ctx: Any, term: Any) -> None:
        label = getattr(term, kind)
        ctx.require_reaction(term, label, kind, f"<{kind}_list>")
        deviation = "deviation" in term.type or "periodicity" in term.type
        if deviation and "periodicity" not in term.type and not ctx.has_tracked_ground_reaction(label):
            raise term.error(f"no column '{label}' in the tracked ground reactions (GRFData)", element=f"<{kind}_list>")
    return bind


SIGNALS: dict[str, Signal] = {
    "generalized_coordinate": Signal(
        "generalized_coordinate", "rad or m", _coordinate_bind,
        lambda v, t: v.coordinate(t.coordinate), lambda v, t: v.tracked_coordinate(t.coordinate)),
    "generalized_speed": Signal(
        "generalized_speed", "rad/s or m/s", _coordinate_bind,
        lambda v, t: v.speed(t.coordinate), lambda v, t: v.tracked_speed(t.coordinate)),
    "generalized_acceleration": Signal(
        "generalized_acceleration", "rad/s^2 or m/s^2", _coordinate_bind,
        lambda v, t: v.acceleration(t.coordinate), lambda v, t: v.tracked_acceleration(t.coordinate)),
    "marker_position": Signal(
        "marker_position", "m", _marker_bind,
        lambda v, t: v.marker_position(t.marker)[:, "xyz".index(t.axis)],
        lambda v, t: v.tracked_marker_position(t.marker)[:, "xyz".index(t.axis)]),
    "marker_velocity": Signal(
        "marker_velocity", "m/s", _marker_bind,
        lambda v, t: v.marker_velocity(t.marker)[:, "xyz".index(t.axis)],
        lambda v, t: v.tracked_marker_velocity(t.marker)[:, "xyz".index(t.axis)]),
    "body_orientation": Signal(
        "body_orientation", "rad", _body_bind,
        lambda v, t: _orientation_column(v.body_orientation(t.body, t.sequence or "xyz"), t),
        lambda v, t: _orientation_column(v.tracked_body_orientation(t.body, t.sequence or "xyz"), t)),
    "external_force": Signal(
        "external_force", "N", _reaction_bind("force"),
        lambda v, t: v.ground_reaction_force(t.force), lambda v, t: v.tracked_ground_reaction_force(t.force)),
    "external_moment": Signal(
        "external_moment", "N·m", _reaction_bind("moment"),
        lambda v, t: v.ground_reaction_moment(t.moment), lambda v, t: v.tracked_ground_reaction_moment(t.moment)),
    "root_segment_residual_load": Signal(
        "root_segment_residual_load", "N·m or N", _load_bind,
        lambda v, t: v.inverse_dynamics_load(t.load)),
}

"""Exact muscle-tendon geometry of path-point muscles, as CasADi expressions.

A muscle's path length is the sum of the straight segments between its *active* path
points in ground, as OpenSim's ``GeometryPath`` computes it without wrapping:

* ``PathPoint``: fixed in its frame;
* ``MovingPathPoint``: x, y, z in its frame are functions of coordinates (OpenSim's
  SimmSpline etc., evaluated exactly by :mod:`nmsm.model.functions`);
* ``ConditionalPathPoint``: active while its coordinate lies in ``[range_min − 1e-5,
  range_max + 1e-5]`` (OpenSim's test, tolerance included). Handled as OpenSim does, not
  smoothed: ``if_else`` on the coordinate, so the length is continuous only where the point
  lies on the segment it replaces, and derivatives are those of the active branch.

Coordinates: the functions take ``q`` with **all** model coordinates in model order
(:attr:`Model.coordinate_names`). Dependent coordinates of enforced coupler constraints
are overwritten by ``scale_factor * f(independent)`` before anything else (their entries
in ``q`` and ``qdot`` are ignored), so every derivative is a total derivative along the
couplers, like a central difference of OpenSim lengths with the coupler assembled.

Moment arms ``r_c = −dL/dq_c`` and lengthening velocity ``V = Σ_c dL/dq_c q̇_c`` come
from CasADi's exact derivatives. Units: m, m/s, rad, rad/s.

Muscles whose path references an *active* wrap object are not exact here (see
:func:`has_active_wrapping`); :mod:`nmsm.model.muscle_geometry` uses surrogates for them.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import casadi as cs
import numpy as np

from nmsm.errors import ModelError
from nmsm.model.components import GROUND, ConditionalPathPoint, Model, MovingPathPoint, Muscle, PathPoint

#: OpenSim's tolerance on a ConditionalPathPoint's range (ConditionalPathPoint::isActive)
CONDITIONAL_RANGE_TOLERANCE = 1e-5


class PathKinematics(Protocol):
    """What the model core's CasADi kinematics provides (:class:`nmsm.model.kinematics.TreeKinematics`)."""

    def forward(self, q: Any) -> dict[str, Any]:
        """Body states (``.R`` 3x3 body->ground, ``.p`` origin in ground) at ``q`` (all coordinates)."""
        ...

    def local_point(self, frame_path: str, point: Any) -> Any:
        """A point given in a frame -> its coordinates in the frame's base body (scale applied)."""
        ...


def has_active_wrapping(model: Model, muscle: Muscle) -> bool:
    """True when the muscle's path references a wrap object that is active."""
    for wrap in muscle.geometry.wraps:
        obj = model.wrap_objects.get(wrap.wrap_object)
        if obj is None:
            raise ModelError(
                f"path wrap references unknown wrap object '{wrap.wrap_object}'",
                file=model.file,
                element=f"muscle '{muscle.name}'",
                expected="a wrap object defined on a body",
            )
        if obj.active:
            return True
    return False


def couple(model: Model, q: Any) -> Any:
    """``q`` (SX/MX column, all coordinates) with dependent coordinates from their couplers."""
    if not model.coupled_coordinates:
        return q
    from nmsm.model.coordinates import CoordinateMap

    coordinate_map = CoordinateMap(model)
    return coordinate_map.expand_q(coordinate_map.independent(q))


class _PoseCache:
    """Body poses at one symbolic ``q`` (the model core's forward kinematics, computed once)."""

    def __init__(self, kinematics: PathKinematics, q: Any) -> None:
        self.kinematics = kinematics
        self.states = kinematics.forward(q)

    def to_ground(self, body: str, point: Any) -> Any:
        """Ground position (3x1) of ``point`` given in ``body``'s frame."""
        if body == GROUND:
            return point
        state = self.states[body]
        return cs.mtimes(state.R, point) + state.p


def _point_in_base(model: Model, kinematics: PathKinematics, point: PathPoint, q: Any, index: dict[str, int]) -> Any:
    """The point's position (3x1) in its base body, at ``q`` (coupled)."""
    if isinstance(point, MovingPathPoint):
        parts = []
        for axis in range(3):
            fn, coord = point.functions[axis], point.coordinates[axis]
            if fn is None:
                parts.append(float(point.location[axis]))
            else:
                if coord is None or coord not in index:
                    raise ModelError(
                        f"moving path point component {'xyz'[axis]} names unknown coordinate '{coord}'",
                        file=model.file,
                        element=f"MovingPathPoint '{point.name}'",
                        expected="a model coordinate",
                    )
                parts.append(fn(q[index[coord]]))
        local = cs.vertcat(*parts)
    else:
        local = cs.DM(point.location.reshape(3, 1))
    if point.frame not in model.frames:
        raise ModelError(f"unknown frame '{point.frame}'", file=model.file, element=f"path point '{point.name}'",
                         expected="a body or offset frame of the model")
    return kinematics.local_point(point.frame, local)


def _active(point: PathPoint, q: Any, index: dict[str, int], model: Model) -> Any | None:
    """0/1 expression for a ConditionalPathPoint, ``None`` for points that are always active."""
    if not isinstance(point, ConditionalPathPoint):
        return None
    if point.coordinate not in index:
        raise ModelError(f"conditional path point names unknown coordinate '{point.coordinate}'", file=model.file,
                         element=f"ConditionalPathPoint '{point.name}'", expected="a model coordinate")
    value = q[index[point.coordinate]]
    lo, hi = point.range
    return cs.logic_and(value >= lo - CONDITIONAL_RANGE_TOLERANCE, value <= hi + CONDITIONAL_RANGE_TOLERANCE)


def path_length(model: Model, muscle: Muscle, poses: _PoseCache, q_coupled: Any) -> Any:
    """Path length (m) of ``muscle`` over its active points, ignoring wrap objects."""
    index = {name: i for i, name in enumerate(model.coordinate_names)}
    points = muscle.geometry.points
    if len(points) < 2:
        raise ModelError("a path needs at least two points", file=model.file, element=f"muscle '{muscle.name}'",
                         expected=">= 2 path points")
    length = 0
    last = None  # ground position of the last active point
    have_last: Any = None  # None: certainly have one (after an always-active point); else 0/1 expression
    for point in points:
        position = poses.to_ground(point.body, _point_in_base(model, poses.kinematics, point, q_coupled, index))
        active = _active(point, q_coupled, index, model)
        if last is None:
            last, have_last = position, active
            continue
        segment = cs.norm_2(position - last)
        if active is None and have_last is None:
            length = length + segment
            last = position
        else:
            use = active if active is not None else 1
            if have_last is not None:
                use = cs.logic_and(use, have_last) if active is not None else have_last
            length = length + cs.if_else(use, segment, 0)
            if active is None:
                last, have_last = position, None
            else:
                last = cs.if_else(active, position, last)
                have_last = None if have_last is None else cs.logic_or(have_last, active)
    return length


class PathMuscleGeometry:
    """Exact lengths, velocities and moment arms of path-point muscles.

    ``kinematics``: the model core's :class:`~nmsm.model.kinematics.TreeKinematics`
    (default: built here; pass one with symbolic parameters for JMP/DO).
    ``muscles``: names (default: every muscle without active wrapping). ``coordinates``:
    the moment-arm coordinates (default: the model's independent coordinates); dependent
    (coupled) coordinates are refused, their effect is inside the total derivatives.
    A muscle with active wrapping raises :class:`ModelError` unless ``allow_wrapping``
    (then its wrap objects are ignored, which is wrong wherever the path wraps).
    """

    def __init__(
        self,
        model: Model,
        kinematics: PathKinematics | None = None,
        muscles: Sequence[str] | None = None,
        coordinates: Sequence[str] | None = None,
        *,
        allow_wrapping: bool = False,
    ) -> None:
        self.model = model
        if kinematics is None:
            from nmsm.model.kinematics import TreeKinematics

            kinematics = TreeKinematics(model)
        self.kinematics = kinematics
        if muscles is None:
            chosen = [m for m in model.muscles if not has_active_wrapping(model, m)]
        else:
            chosen = [model.muscle(name) for name in muscles]
        if not allow_wrapping:
            wrapping = [m.name for m in chosen if has_active_wrapping(model, m)]
            if wrapping:
                raise ModelError(
                    f"muscles with active wrap objects have no exact path geometry: {', '.join(wrapping)}",
                    file=model.file,
                    element="muscles",
                    expected="path-point muscles (use a surrogate for wrapping muscles)",
                )
        self.muscles: tuple[str, ...] = tuple(m.name for m in chosen)
        self._muscles = chosen
        dependents = set(model.coupled_coordinates)
        names = model.coordinate_names
        self.coordinates: tuple[str, ...] = tuple(
            [c for c in names if c not in dependents] if coordinates is None else coordinates
        )
        bad = [c for c in self.coordinates if c not in names or c in dependents]
        if bad:
            raise ModelError(
                f"not independent model coordinates: {', '.join(bad)}",
                file=model.file,
                element="coordinate list",
                expected="independent coordinates of the model (dependent coupled ones follow their coupler)",
            )

    def lengths_expression(self, q: Any) -> Any:
        """Lengths ``(n_m, 1)`` (m) of the muscles at ``q`` (all model coordinates, SX/MX)."""
        qc = couple(self.model, q)
        poses = _PoseCache(self.kinematics, qc)
        values = [path_length(self.model, m, poses, qc) for m in self._muscles]
        return cs.vertcat(*values) if values else cs.SX(0, 1)

    def function(self, name: str = "path_muscle_geometry") -> cs.Function:
        """Per-frame SX function ``(q, qdot) -> (lengths, velocities, moment_arms)``.

        ``q``, ``qdot`` ``(n_q, 1)``: all model coordinates in model order (dependent
        entries ignored). Outputs ``lengths`` ``(n_m, 1)`` m, ``velocities`` ``(n_m, 1)``
        m/s, ``moment_arms`` ``(n_m, n_c)`` m over :attr:`coordinates`.
        """
        n_q = len(self.model.coordinates)
        q = cs.SX.sym("q", n_q)
        qdot = cs.SX.sym("qdot", n_q)
        lengths = self.lengths_expression(q)
        jac = cs.jacobian(lengths, q)
        index = [self.model.coordinate_index(c) for c in self.coordinates]
        arms = -jac[:, index] if index else cs.SX(len(self.muscles), 0)
        velocities = cs.mtimes(jac, qdot)
        return cs.Function(name, [q, qdot], [lengths, velocities, arms], ["q", "qdot"],
                           ["lengths", "velocities", "moment_arms"])


def evaluate_function(function: cs.Function, q: np.ndarray, qdot: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """Evaluate a per-frame geometry function over frames ``q`` ``(n, n_in)``.

    Returns ``lengths`` ``(n, n_m)``, ``velocities`` ``(n, n_m)`` and ``moment_arms``
    ``(n, n_m, n_c)``.
    """
    q = np.atleast_2d(np.asarray(q, dtype=float))
    qdot = np.zeros_like(q) if qdot is None else np.atleast_2d(np.asarray(qdot, dtype=float))
    n = q.shape[0]
    mapped = function.map(n)
    lengths, velocities, arms = mapped(q.T, qdot.T)
    n_m = function.size1_out(0)
    n_c = function.size2_out(2)
    arms = np.asarray(arms).reshape(n_m, n, n_c).transpose(1, 0, 2)
    return np.asarray(lengths).T.reshape(n, n_m), np.asarray(velocities).T.reshape(n, n_m), arms

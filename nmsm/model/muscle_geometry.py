"""The muscle-geometry provider: exact paths where possible, surrogates for wrapping muscles.

:class:`MuscleGeometry` gives MTP, NCP and Treatment Optimization one per-frame CasADi
function for a muscle set and a coordinate list::

    geometry = MuscleGeometry(model, muscles, coordinates, surrogate=SurrogateModel.load(path))
    f = geometry.function()       # (q[n_q], qdot[n_q]) -> (lengths[n_m], velocities[n_m], moment_arms[n_m x n_c])
    L, V, R = f.map(n_frames, "thread", 2)(Q, Qdot)   # Q: (n_q, n_frames), all model coordinates

* muscles without an active wrap object: exact path-point geometry
  (:mod:`nmsm.model.muscle_paths`), couplers applied inside;
* muscles with active wrapping: the surrogate (:mod:`nmsm.model.surrogate`), which
  must cover them; its moment arms are zero on coordinates outside its list.

``q``/``qdot`` hold all model coordinates in model order (dependent entries ignored).
Units: m, m/s, rad, rad/s; moment arms ``−dL/dq`` in m.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import casadi as cs

from nmsm.errors import ModelError
from nmsm.model.components import Model
from nmsm.model.muscle_paths import PathMuscleGeometry, has_active_wrapping
from nmsm.model.surrogate import SurrogateModel

PATH = "path"
SURROGATE = "surrogate"


class MuscleGeometry:
    """Geometry of ``muscles`` over moment-arm ``coordinates`` (see the module docstring).

    ``prefer_surrogate``: use the surrogate also for path-point muscles it covers (as the
    original's synergy controller does for every muscle). ``kinematics``: the model core's
    :class:`~nmsm.model.kinematics.TreeKinematics` (default: built here).
    """

    def __init__(
        self,
        model: Model,
        muscles: Sequence[str] | None = None,
        coordinates: Sequence[str] | None = None,
        *,
        surrogate: SurrogateModel | None = None,
        prefer_surrogate: bool = False,
        kinematics: Any = None,
    ) -> None:
        self.model = model
        self.surrogate = surrogate
        self.muscles: tuple[str, ...] = tuple(model.muscle_names if muscles is None else muscles)
        dependents = set(model.coupled_coordinates)
        self.coordinates: tuple[str, ...] = tuple(
            [c for c in model.coordinate_names if c not in dependents] if coordinates is None else coordinates
        )
        covered = set(surrogate.muscle_names) if surrogate is not None else set()
        self.sources: dict[str, str] = {}
        missing = []
        for name in self.muscles:
            wraps = has_active_wrapping(model, model.muscle(name))
            if name in covered and (wraps or prefer_surrogate):
                self.sources[name] = SURROGATE
            elif not wraps:
                self.sources[name] = PATH
            else:
                missing.append(name)
        if missing:
            raise ModelError(
                f"muscles with active wrapping need a surrogate: {', '.join(missing)}",
                file=model.file,
                element="muscles",
                expected="a surrogate model covering them (nmsm surrogate ...)",
            )
        path_muscles = [m for m in self.muscles if self.sources[m] == PATH]
        self._paths = (PathMuscleGeometry(model, kinematics, path_muscles, self.coordinates)
                       if path_muscles else None)
        self._path_muscles = path_muscles
        self._surrogate_muscles = [m for m in self.muscles if self.sources[m] == SURROGATE]

    def function(self, name: str = "muscle_geometry") -> cs.Function:
        """Per-frame SX function ``(q, qdot) -> (lengths, velocities, moment_arms)`` (module docstring)."""
        names = self.model.coordinate_names
        n_q = len(names)
        q = cs.SX.sym("q", n_q)
        qdot = cs.SX.sym("qdot", n_q)
        rows: dict[str, tuple[Any, Any, Any]] = {}
        if self._paths is not None:
            lengths, velocities, arms = self._paths.function()(q, qdot)
            for i, m in enumerate(self._path_muscles):
                rows[m] = (lengths[i], velocities[i], arms[i, :])
        if self._surrogate_muscles:
            assert self.surrogate is not None
            lengths, velocities, arms = self.surrogate.function(names, self._surrogate_muscles)(q, qdot)
            columns = [names.index(c) for c in self.coordinates]
            for i, m in enumerate(self._surrogate_muscles):
                rows[m] = (lengths[i], velocities[i], arms[i, columns] if columns else cs.SX(1, 0))
        lengths = cs.vertcat(*[rows[m][0] for m in self.muscles]) if self.muscles else cs.SX(0, 1)
        velocities = cs.vertcat(*[rows[m][1] for m in self.muscles]) if self.muscles else cs.SX(0, 1)
        arms = cs.vertcat(*[rows[m][2] for m in self.muscles]) if self.muscles else cs.SX(0, len(self.coordinates))
        return cs.Function(name, [q, qdot], [lengths, velocities, arms], ["q", "qdot"],
                           ["lengths", "velocities", "moment_arms"])

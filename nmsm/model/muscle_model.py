"""Muscle forces and joint moments of the muscle and synergy controllers (docs/model.md, docs/treatment.md).

Geometry comes from a fitted surrogate (:mod:`nmsm.model.surrogate`: lengths, velocities
and moment arms as polynomials of the surrogate coordinates); forces from the rigid-tendon
Hill model (:mod:`nmsm.model.hill`)::

    l̃ = (L - l_ts) / (l_o cos α),   ṽ = V / (vmax l_o cos α)
    F = F0 (a f_L(l̃) f_V(ṽ) + f_P(l̃)) cos α,   M_j = Σ_m r_mj F_m

Parameters per muscle: ``max_isometric_force`` F0 (N), ``optimal_fiber_length`` l_o (m),
``tendon_slack_length`` l_ts (m) from the ``.osimx`` when it has them (matched by name; the
original matches by list position, a bug; an ``.osimx`` muscle that the model lacks is an
error) else from the ``.osim``; pennation α (rad) from the
``.osim``; ``vmax`` = ``maximum_shortening_velocity_multiplier`` (l_o/s). Parameters may be
replaced by CasADi expressions (Design Optimization model modifiers).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.row_map import map_rows
from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel, check_muscles_in_model
from nmsm.model import hill
from nmsm.model.surrogate import SurrogateModel

PARAMETERS = ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length")


@attrs.define
class MuscleModel:
    """Muscles of a controller: names, surrogate geometry, Hill parameters.

    ``parameters[name]`` -> {``max_isometric_force``, ``optimal_fiber_length``,
    ``tendon_slack_length``}: floats or MX expressions; ``pennation`` (M,) rad.
    """

    muscles: tuple[str, ...]
    coordinates: tuple[str, ...]
    surrogate: SurrogateModel
    parameters: dict[str, dict[str, Any]]
    pennation: np.ndarray
    vmax_factor: float = hill.DEFAULT_VMAX_FACTOR
    _function: cs.Function | None = attrs.field(default=None, init=False, repr=False)

    @classmethod
    def build(cls, muscles: Sequence[str], coordinates: Sequence[str], surrogate: SurrogateModel, osim_model: Any,
              osimx: Any, vmax_factor: float, *, where: Any = None) -> MuscleModel:
        """Parameters from the ``.osim`` model (``nmsm.model.Model``) and ``.osimx`` overrides."""
        missing = [m for m in muscles if m not in surrogate.muscle_names]
        if missing:
            raise InputError(f"muscle(s) {', '.join(missing)} have no surrogate geometry (no moment arm above epsilon "
                             "on the surrogate coordinates, or missing from the surrogate data)", file=where,
                             element="<surrogate_model_coordinate_list>",
                             expected="surrogate coordinates spanned by every synergy muscle")
        params: dict[str, dict[str, Any]] = {}
        pennation = []
        overrides = getattr(osimx, "muscles", {}) if osimx is not None else {}
        if isinstance(osimx, OsimxModel):
            check_muscles_in_model(osimx, osim_model.muscle_names, model_file=getattr(osim_model, "file", None))
        for name in muscles:
            try:
                muscle = osim_model.muscle(name)
            except KeyError as exc:
                raise InputError(str(exc), file=where, expected="muscles of the model") from exc
            values = {key: float(getattr(muscle, key)) for key in PARAMETERS}
            override = overrides.get(name)
            if override is not None:
                for key in PARAMETERS:
                    value = getattr(override, key, None)
                    if value is not None:
                        values[key] = float(value)
            params[name] = values
            pennation.append(float(muscle.pennation_angle_at_optimal))
        return cls(tuple(muscles), tuple(coordinates), surrogate, params, np.asarray(pennation), float(vmax_factor))

    @property
    def n(self) -> int:
        return len(self.muscles)

    def set_parameter(self, muscle: str, name: str, value: Any) -> None:
        """Replace a parameter (``PARAMETERS``) of ``muscle`` by a value or MX expression."""
        if muscle not in self.parameters:
            raise KeyError(f"muscle '{muscle}' is not driven by this controller (have: {', '.join(self.muscles)})")
        if name not in PARAMETERS:
            raise KeyError(f"unknown muscle parameter '{name}' (expected one of {', '.join(PARAMETERS)})")
        self.parameters[muscle][name] = value

    def parameter_row(self) -> cs.MX:
        """(1, 3 M) [F0..., l_o..., l_ts...] as MX (constants or modifier expressions)."""
        cols = [cs.MX(self.parameters[m][key]) for key in PARAMETERS for m in self.muscles]
        return cs.horzcat(*cols)

    def point_function(self) -> cs.Function:
        """SX ``(q_c, qd_c, a, p) -> (forces (M,), moments (n_c,), l̃ (M,), ṽ (M,))`` of one point;
        ``q_c``/``qd_c`` over :attr:`coordinates`, ``a`` activations, ``p`` = parameter row."""
        if self._function is None:
            geometry = self.surrogate.function(self.coordinates, self.muscles)
            nc, M = len(self.coordinates), self.n
            q, qd, a = cs.SX.sym("q", nc), cs.SX.sym("qd", nc), cs.SX.sym("a", M)
            p = cs.SX.sym("p", 3 * M)
            F0, lo, lts = p[:M], p[M:2 * M], p[2 * M:]
            lengths, velocities, arms = geometry(q, qd)
            forces, l_norm, v_norm = self.tendon_forces(a, lengths, velocities, F0, lo, lts)
            moments = cs.mtimes(arms.T, forces)
            self._function = cs.Function("muscle_forces", [q, qd, a, p], [forces, moments, l_norm, v_norm])
        return self._function

    def tendon_forces(self, a: Any, lengths: Any, velocities: Any, F0: Any, lo: Any, lts: Any) -> tuple[Any, Any, Any]:
        """(tendon forces N, normalized fiber lengths, normalized fiber velocities), each (M,),
        of activations ``a``, musculotendon lengths (m) and velocities (m/s) and the muscles'
        maximum isometric forces ``F0`` (N), optimal fiber lengths ``lo`` and tendon slack
        lengths ``lts`` (m): the rigid-tendon Hill model."""
        alpha = cs.DM(self.pennation)
        l_norm = hill.normalized_fiber_length(lengths, lo, lts, alpha)
        v_norm = hill.normalized_fiber_velocity(velocities, lo, alpha, self.vmax_factor)
        return hill.tendon_force(a, l_norm, v_norm, F0, alpha), l_norm, v_norm

    def evaluate(self, view: Any, activations: cs.MX, parallel: int = 1) -> list[cs.MX]:
        """[forces (n, M), moments (n, n_c), l̃ (n, M), ṽ (n, M)] on a grid view."""
        if hasattr(view, "map_kinematics_function"):
            return view.map_kinematics_function(("muscles", id(self)), self.point_function(), "q, qd",
                                                self.coordinates, (activations, self.parameter_row()))
        Q = cs.horzcat(*[view.coordinate(c) for c in self.coordinates])
        Qd = cs.horzcat(*[view.speed(c) for c in self.coordinates])
        return map_rows(self.point_function(), Q, Qd, activations, self.parameter_row(), parallel=parallel)


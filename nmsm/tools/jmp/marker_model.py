"""Model markers as CasADi functions of the free coordinates and the model parameters.

:class:`MarkerKinematics` decides which coordinates a set of markers can determine and
builds one SX function per frame:

* **free** coordinates: independent (not the dependent side of an enforced
  CoordinateCouplerConstraint), not locked, and moving at least one of the markers;
* **locked** coordinates sit at their ``default_value`` (as OpenSim's IK locks them);
* **insensitive** coordinates (no marker moves with them, e.g. the wrist without hand
  markers) are held at their default value and reported, unless named in ``extra_free``
  (e.g. tracked by an IK coordinate task);
* **dependent** coordinates follow their couplers, ``beta = s * f(q)``: never variables.

Bounds are the coordinate ranges of clamped coordinates (OpenSim's assembler restricts
only those), unbounded otherwise. Units: rad for rotational, m for translational
coordinates; marker positions in m, ground frame.

Markers of a body listed in ``unscaled_marker_bodies`` keep their file location when the
body is scaled by a :class:`~nmsm.model.parameters.ModelParameters` scale factor (JMP
scales a body and then restores its markers, unless ``anatomical_markers`` is set).
"""

from __future__ import annotations

from collections.abc import Collection, Sequence

import casadi as cs
import numpy as np

from nmsm.core.threads import SOLVER_THREADS
from nmsm.errors import InputError
from nmsm.model.casadi_model import CasadiModel
from nmsm.model.components import GROUND, Model
from nmsm.model.parameters import ModelParameters


class MarkerKinematics:
    """Positions of ``marker_names`` as functions of the free coordinates (see module docstring)."""

    def __init__(self, model: Model, marker_names: Sequence[str], parameters: ModelParameters | None = None, *,
                 unscaled_marker_bodies: Collection[str] = (), extra_free: Collection[str] = ()) -> None:
        missing = [n for n in marker_names if n not in model.marker_names]
        if missing:
            raise InputError(f"marker(s) {', '.join(missing)} not in the model", file=model.file,
                             element="<MarkerSet>", expected="markers of the model")
        self.model = model
        self.marker_names = tuple(marker_names)
        self.parameters = parameters if parameters is not None else ModelParameters(model)
        self.casadi_model = CasadiModel(model, self.parameters)
        self.coordinate_map = self.casadi_model.coordinates
        self.unscaled_marker_bodies = frozenset(unscaled_marker_bodies)
        names = model.coordinate_names
        self.coordinate_names = tuple(names)
        independent = self.coordinate_map.independent_names
        locked = [n for n in independent if model.coordinate(n).locked]
        candidates = [n for n in independent if n not in locked]
        self.locked_names = tuple(locked)
        self.default_independent = np.array([model.coordinate(n).default_value for n in independent], dtype=float)

        q_all = cs.SX.sym("q_candidates", len(candidates))
        positions = self._positions(self._full(q_all, candidates))
        sensitive = set(cs.jacobian(cs.vec(positions), q_all).sparsity().get_col())
        extra = set(extra_free)
        self.free_names = tuple(n for k, n in enumerate(candidates) if k in sensitive or n in extra)
        self.insensitive_names = tuple(n for k, n in enumerate(candidates) if k not in sensitive and n not in extra)

        self.q = cs.SX.sym("q", len(self.free_names))
        self.p = self.parameters.symbols
        self.q_full = self._full(self.q, self.free_names)
        self.positions = self._positions(self.q_full)  # 3 x M SX
        self.position_function = cs.Function("marker_positions", [self.q, self.p], [self.positions], ["q", "p"],
                                             ["markers"])
        self.full_function = cs.Function("full_coordinates", [self.q], [self.q_full], ["q"], ["q_full"])
        lower, upper = [], []
        for n in self.free_names:
            c = model.coordinate(n)
            lower.append(c.range[0] if c.clamped else -np.inf)
            upper.append(c.range[1] if c.clamped else np.inf)
        self.lower = np.array(lower, dtype=float)
        self.upper = np.array(upper, dtype=float)

    # ------------------------------------------------------------------ building blocks
    def _full(self, q: cs.SX, names: Sequence[str]) -> cs.SX:
        """Full coordinate vector (model order): ``names`` from ``q``, other independent ones
        at their defaults, dependent ones through the couplers."""
        index = {n: k for k, n in enumerate(names)}
        parts = []
        for k, n in enumerate(self.coordinate_map.independent_names):
            parts.append(q[index[n]] if n in index else cs.SX(float(self.default_independent[k])))
        return self.coordinate_map.expand_q(cs.vertcat(*parts)) if parts else cs.SX(0, 1)

    def _positions(self, q_full: cs.SX) -> cs.SX:
        kin = self.casadi_model.kinematics
        states = kin.forward(q_full)
        columns = []
        for name in self.marker_names:
            index = self.model.marker_names.index(name)
            marker = self.model.markers[index]
            if marker.body == GROUND:
                columns.append(cs.DM(marker.location))
                continue
            state = states[marker.body]
            if marker.body in self.unscaled_marker_bodies and marker.body in self.parameters.scales:
                rotation, origin = self._frame_in_body_unscaled(marker.frame)
                location = self.parameters.marker_locations.get(name)
                location = cs.DM(marker.location) if location is None else location
                local = origin + cs.mtimes(rotation, location)
            else:
                local = kin.marker_in_body(index)
            columns.append(state.p + cs.mtimes(state.R, local))
        return cs.horzcat(*columns) if columns else cs.SX(3, 0)

    def _frame_in_body_unscaled(self, frame_path: str) -> tuple[cs.DM, cs.DM]:
        frame = self.model.frames[frame_path]
        if frame.kind != "offset":
            return cs.DM.eye(3), cs.DM.zeros(3, 1)
        return cs.DM(frame.rotation_in_base), cs.DM(frame.origin_in_base)

    # ------------------------------------------------------------------ numeric helpers
    @property
    def n_free(self) -> int:
        return len(self.free_names)

    @property
    def n_markers(self) -> int:
        return len(self.marker_names)

    def initial_free(self) -> np.ndarray:
        """Default values of the free coordinates, clipped into their bounds (``(n_free,)``)."""
        index = {n: k for k, n in enumerate(self.coordinate_map.independent_names)}
        values = np.array([self.default_independent[index[n]] for n in self.free_names], dtype=float)
        return np.clip(values, self.lower, self.upper)

    def full_coordinates(self, q_free: np.ndarray) -> np.ndarray:
        """Full coordinates ``(F, n_coordinates)`` (model order) from free ones ``(F, n_free)``."""
        q_free = np.atleast_2d(np.asarray(q_free, dtype=float))
        if q_free.shape[0] == 0:
            return np.zeros((0, len(self.coordinate_names)))
        mapped = self.full_function.map(q_free.shape[0])
        return np.asarray(mapped(q_free.T)).T.reshape(q_free.shape[0], len(self.coordinate_names))

    def marker_positions(self, q_free: np.ndarray, p: np.ndarray | None = None) -> np.ndarray:
        """Marker positions ``(F, M, 3)`` (m) for free coordinates ``(F, n_free)``."""
        q_free = np.atleast_2d(np.asarray(q_free, dtype=float))
        p = self.parameters.initial_values if p is None else np.asarray(p, dtype=float)
        n = q_free.shape[0]
        out = np.asarray(self.position_function.map(n, "thread", SOLVER_THREADS)(q_free.T, p))  # 3 x (M n)
        return out.reshape(3, self.n_markers, n, order="F").transpose(2, 1, 0)

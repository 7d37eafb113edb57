"""What a transcription discretizes (:class:`Phase`) and what it returns (:class:`Trajectory`).

A tool declares one :class:`Phase` - named states and controls with bounds, scaling and an
initial guess on the mesh, the dynamics ``dx/dt = f(x, u, p)`` as a per-point CasADi
function, and a fixed or free final time - and hands it with an
:class:`~nmsm.core.problem.OptimizationProblem` to a :class:`Transcription`
(``RadauCollocation``, ``TrapezoidalCollocation``). The transcription declares the
problem's variables and defect constraints and returns a :class:`Trajectory`: the phase's
states, controls and times as MX expressions on named grids (see
:mod:`~nmsm.core.transcription.mesh`), the quadrature of the cost integrals,
and sampling of a solution on those grids.
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.transcription.mesh import Mesh


@attrs.frozen
class FinalTime:
    """The phase duration ``t_f`` (s); the phase starts at 0.

    Fixed when ``lower == upper``; otherwise a design variable in ``[lower, upper]``
    starting at ``guess``.
    """

    guess: float
    lower: float
    upper: float

    @classmethod
    def fixed(cls, value: float) -> FinalTime:
        return cls(float(value), float(value), float(value))

    @property
    def is_free(self) -> bool:
        return self.upper > self.lower

    def __attrs_post_init__(self) -> None:
        if not (0 < self.lower <= self.upper):
            raise ValueError(f"final time bounds must satisfy 0 < lower <= upper, got [{self.lower}, {self.upper}]")
        if not (self.lower - 1e-12 <= self.guess <= self.upper + 1e-12):
            raise ValueError(f"final time guess {self.guess} outside [{self.lower}, {self.upper}]")


@attrs.define
class Block:
    """Named columns of states or controls: bounds (n,), scale/offset (n,) or None."""

    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    guess: np.ndarray  # (rows, n) on the transcription's rows for this block
    scale: np.ndarray | None = None
    offset: np.ndarray | None = None

    def __attrs_post_init__(self) -> None:
        n = len(self.names)
        self.lower = np.broadcast_to(np.asarray(self.lower, dtype=float), (n,)).copy()
        self.upper = np.broadcast_to(np.asarray(self.upper, dtype=float), (n,)).copy()
        self.guess = np.asarray(self.guess, dtype=float).reshape(-1, n) if n else np.zeros((0, 0))
        if len(set(self.names)) != n:
            raise ValueError(f"duplicate names in {self.names}")


@attrs.define
class Phase:
    """A single-phase optimal control problem to transcribe.

    ``dynamics`` maps ``(x (nx,), u (nu,), p (np,))`` to ``dx/dt`` (nx,) in physical time
    (per point, preferably SX); ``parameters`` is the MX vector passed as ``p`` (static
    design variables or constants). Guesses: states on the mesh nodes ``(K + 1, nx)``,
    controls on the collocation points ``(K, nu)``.
    """

    mesh: Mesh
    states: Block
    controls: Block
    dynamics: cs.Function
    final_time: FinalTime
    parameters: cs.MX = attrs.field(factory=lambda: cs.MX(0, 1))

    def __attrs_post_init__(self) -> None:
        nx, nu = len(self.states.names), len(self.controls.names)
        if self.states.guess.shape != (self.mesh.n_nodes, nx):
            raise ValueError(f"state guess has shape {self.states.guess.shape}, expected {(self.mesh.n_nodes, nx)}")
        if nu and self.controls.guess.shape != (self.mesh.n_collocation, nu):
            raise ValueError(
                f"control guess has shape {self.controls.guess.shape}, expected {(self.mesh.n_collocation, nu)}"
            )
        overlap = set(self.states.names) & set(self.controls.names)
        if overlap:
            raise ValueError(f"names used for both states and controls: {sorted(overlap)}")


class Trajectory(abc.ABC):
    """The transcribed phase: MX expressions on named grids, quadrature, sampling."""

    phase: Phase
    problem: OptimizationProblem

    # ---- symbolic access ------------------------------------------------------------------
    @property
    @abc.abstractmethod
    def final_time(self) -> cs.MX:
        """``t_f`` (s): a variable when free, else a constant."""

    @abc.abstractmethod
    def grid_size(self, grid: str) -> int:
        """Number of rows of ``grid``."""

    @abc.abstractmethod
    def normalized_times(self, grid: str) -> np.ndarray:
        """(n,) normalized times ``s = t / t_f`` of the grid's rows."""

    @abc.abstractmethod
    def states(self, grid: str) -> cs.MX:
        """(n, nx) state values on ``grid``."""

    @abc.abstractmethod
    def controls(self, grid: str) -> cs.MX:
        """(n, nu) control values on ``grid`` (interpolated where controls are not variables)."""

    @property
    @abc.abstractmethod
    def integration_grid(self) -> str:
        """The grid whose rows :attr:`quadrature_weights` refers to."""

    @property
    @abc.abstractmethod
    def quadrature_weights(self) -> np.ndarray:
        """(n,) weights on :attr:`integration_grid` for ``integral_0^1 g(s) ds`` (sum 1)."""

    def times(self, grid: str) -> cs.MX:
        """(n, 1) times (s) of the grid's rows."""
        return cs.DM(self.normalized_times(grid)) * self.final_time

    def state(self, name: str, grid: str) -> cs.MX:
        return self.states(grid)[:, self._index(self.phase.states.names, name, "state")]

    def control(self, name: str, grid: str) -> cs.MX:
        return self.controls(grid)[:, self._index(self.phase.controls.names, name, "control")]

    @staticmethod
    def _index(names: Sequence[str], name: str, what: str) -> int:
        try:
            return list(names).index(name)
        except ValueError:
            raise KeyError(f"no {what} named '{name}' (have: {', '.join(names)})") from None

    # ---- numeric sampling -------------------------------------------------------------------
    @abc.abstractmethod
    def sample(self, solution: Solution | dict[str, np.ndarray], grid: str | np.ndarray = "nodes") -> dict[str, Any]:
        """Numeric ``time`` (n,), ``states`` (n, nx), ``controls`` (n, nu) of a solution on a
        named grid or at normalized times (an array in [0, 1])."""


class Transcription(abc.ABC):
    """Turns a :class:`Phase` into variables and constraints of an OptimizationProblem."""

    name: str = ""

    @abc.abstractmethod
    def transcribe(self, phase: Phase, problem: OptimizationProblem, *, prefix: str = "") -> Trajectory:
        """Declare the phase's variables and defect constraints in ``problem``."""


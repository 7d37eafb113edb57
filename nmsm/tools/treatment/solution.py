"""Numeric values of a solved (or evaluated) treatment problem on an output grid.

Quantities are the context's own expressions evaluated at the solution, so what is
written is exactly what the terms saw. The output grid is ``nodes`` (the collocation
points and the phase end, as the original writes its files).
"""

from __future__ import annotations

from functools import cached_property
from typing import Any

import casadi as cs
import numpy as np

from nmsm.core.problem import Solution
from nmsm.tools.treatment.formulation import ACCEL_PREFIX, TreatmentProblem


class TreatmentSolution:
    """Values of a :class:`TreatmentProblem` at a scaled point (``Solution.x_scaled``)."""

    def __init__(self, built: TreatmentProblem, solution: Solution, trial_name: str, grid: str = "nodes") -> None:
        self.built = built
        self.solution = solution
        self.trial_name = trial_name
        self.grid = grid
        self.view = built.context.at(grid)

    def value(self, expression: Any) -> np.ndarray:
        """Numeric value of an MX expression of the problem at this solution."""
        return np.asarray(self.built.problem.evaluate(cs.MX(expression), self.solution.x_scaled))

    @cached_property
    def time(self) -> np.ndarray:
        return self.value(self.view.time()).ravel()

    @cached_property
    def final_time(self) -> float:
        return float(self.value(self.built.trajectory.final_time).ravel()[0])

    @cached_property
    def positions(self) -> np.ndarray:
        """(n, nq) all coordinates (rad, m), model order."""
        return self.value(self.view.positions())

    @cached_property
    def speeds(self) -> np.ndarray:
        return self.value(self.view.speeds())

    @cached_property
    def accelerations(self) -> np.ndarray:
        return self.value(self.view.accelerations())

    @cached_property
    def inverse_dynamics(self) -> np.ndarray:
        """(n, nq) inverse-dynamics loads (N·m, N), model order."""
        return self.value(self.view.inverse_dynamics())

    @cached_property
    def _controls(self) -> np.ndarray:
        return self.value(self.built.trajectory.controls(self.grid))

    def control(self, name: str) -> np.ndarray:
        """(n, 1) values of a control by internal name (e.g. ``torque:knee_angle_r``)."""
        names = self.built.trajectory.phase.controls.names
        return self._controls[:, [list(names).index(name)]]

    @cached_property
    def _all_states(self) -> np.ndarray:
        return self.value(self.built.trajectory.states(self.grid))

    @property
    def states(self) -> np.ndarray:
        """(n, 2 n_s) [q_s, q̇_s] (the controllers' own states: :meth:`controller_state`)."""
        return self._all_states[:, :2 * len(self.built.data.state_coordinates)]

    def controller_state(self, name: str) -> np.ndarray:
        """(n, 1) values of a controller's own state by internal name."""
        names = list(self.built.trajectory.phase.states.names)
        if name not in names:
            raise KeyError(f"no state named '{name}' (have: {', '.join(names)})")
        return self._all_states[:, [names.index(name)]]

    @property
    def state_accelerations(self) -> np.ndarray:
        sc = self.built.data.state_coordinates
        return np.hstack([self.control(ACCEL_PREFIX + c) for c in sc]) if sc else np.zeros((self.time.size, 0))

    def muscle_activations(self) -> np.ndarray:
        return self.value(self.view.muscle_activations())

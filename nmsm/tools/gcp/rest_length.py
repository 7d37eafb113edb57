"""Initial resting spring length (``initialize_resting_spring_length`` of the original).

Before the tasks, ``L0`` alone is fitted to the vertical ground reaction of every foot
with everything else at its initial value (spring constants, damping, kinematic
coefficients 1): residuals ``(F_y,model - F_y,exp) / sqrt(T)`` per foot.

The original fits a variant of the contact model here (transition curvature 5e-4, no
clamp of the height, damping with the opposite sign); nmsm fits the same model the tasks
use, so the starting point is consistent with the first task.
"""

from __future__ import annotations

from collections.abc import Sequence

import casadi as cs

from nmsm.core import reductions
from nmsm.core.problem import OptimizationProblem
from nmsm.io.settings.gcp import DESIGN_FLAGS
from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.problem import build_design
from nmsm.tools.gcp.state import GcpState
from nmsm.tools.gcp.values import foot_values


def initialize_resting_length(feet: Sequence[FootInputs], state: GcpState, *, max_iterations: int = 100) -> GcpState:
    """``state`` with its resting spring length fitted to the vertical forces."""
    problem = OptimizationProblem("gcp_resting_length")
    flags = {flag: flag == "restingSpringLength" for flag in DESIGN_FLAGS}
    design = build_design(problem, state, flags)
    for i, foot in enumerate(feet):
        values = foot_values(foot, design, i)
        error = values.forces[1, :] - values.experimental_forces[1, :]
        problem.add_cost(f"vertical_grf_foot_{foot.index}", reductions.mean_square(cs.vec(error)))
    solution = problem.solve("least_squares", ftol=1e-12, xtol=1e-12, gtol=1e-12, max_nfev=max_iterations)
    new = state.copy()
    new.resting_spring_length = float(solution.values["resting_length"].ravel()[0])
    return new

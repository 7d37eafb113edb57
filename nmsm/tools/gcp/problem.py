"""One GCP task as an :class:`~nmsm.core.problem.OptimizationProblem`.

The task's flags choose the design-variable blocks; everything else is
held at the current :class:`~nmsm.tools.gcp.state.GcpState`. Variable names, bounds and
scales:

==============================  ====================  ================  =========
block                           name                  bounds            scale
==============================  ====================  ================  =========
``springConstants``             spring_constants      [0, inf) N/m      1000 N/m
``dampingFactor``               damping_factor        [0, inf) s/m      1
``dynamicFrictionCoefficient``  dynamic_friction      [0, inf)          1
``viscousFrictionCoefficient``  viscous_friction      [0, inf) s/m      1
``restingSpringLength``         resting_length        free (m)          0.01 m
``kinematicsBSplineCoefficients`` coefficients_<foot> free (m, 7)       1
``electricalCenterX/Y/Z``       ec_<axis>_<foot>      free (m)          0.01 m
``forcePlateRotation``          plate_rotation_<foot> +-0.2618 rad      (range)
==============================  ====================  ================  =========

``<foot>`` is the 1-based foot index. Solved by the back end ``lifted_least_squares``
(:mod:`nmsm.core.backends.lifted_least_squares`: scipy ``least_squares`` 'trf', exact sparse
Jacobians through the lifted foot coordinates, LSMR trust-region steps: the Jacobian has
~40 times more rows than columns and an SVD of it per iteration costs more than the
Jacobian itself, for the same steps here). Options from the settings: ``function_tolerance`` -> ``ftol``,
``step_tolerance`` -> ``xtol``, ``optimality_tolerance`` -> ``gtol``, ``max_iterations``
-> the number of residual evaluations (each trust-region iteration evaluates the residuals
once and the Jacobian once per accepted step). ``diff_min_change`` (a finite-difference
step) does not apply to exact derivatives.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.term import Term
from nmsm.io.settings.gcp import GcpTask, GroundContactPersonalizationSettings
from nmsm.tools.gcp.context import GcpContext
from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.state import Design, GcpState
from nmsm.tools.gcp.values import FootValues, foot_coordinates, foot_values

#: bound of the force-plate rotation (rad), 15 degrees
PLATE_ROTATION_BOUND = 0.2618
_AXES = "xyz"


@attrs.frozen(eq=False)
class TaskProblem:
    """A built task: the problem, its context (for terms) and the modeled values.

    With lifting, the problem's lifted parameters (``problem.lifted``) are the foot
    coordinates ``q_<foot>`` and rates ``qdot_<foot>`` (7, T), standing for their expressions
    of the design variables.
    """

    problem: OptimizationProblem
    context: GcpContext
    values: list[FootValues]
    design: Design
    terms: list[Term]


def _scalar(problem: OptimizationProblem, optimize: bool, name: str, value: float, **kw: Any) -> Any:
    if not optimize:
        return cs.DM(value)
    return problem.variable(name, [value], **kw)


def build_design(problem: OptimizationProblem, state: GcpState, flags: dict[str, bool]) -> Design:
    """The task's :class:`Design`: variables for the flagged blocks, numbers elsewhere."""
    inf = np.inf
    k = (problem.variable("spring_constants", state.spring_constants, 0.0, inf, scale=1000.0)
         if flags["springConstants"] else cs.DM(state.spring_constants))
    damping = _scalar(problem, flags["dampingFactor"], "damping_factor", state.damping_factor,
                      lower=0.0, upper=inf, scale=1.0)
    mu_d = _scalar(problem, flags["dynamicFrictionCoefficient"], "dynamic_friction",
                   state.dynamic_friction_coefficient, lower=0.0, upper=inf, scale=1.0)
    mu_v = _scalar(problem, flags["viscousFrictionCoefficient"], "viscous_friction",
                   state.viscous_friction_coefficient, lower=0.0, upper=inf, scale=1.0)
    rest = _scalar(problem, flags["restingSpringLength"], "resting_length", state.resting_spring_length,
                   scale=0.01)
    coefficients, shifts, rotations = [], [], []
    for i, c in enumerate(state.coefficients):
        foot = i + 1
        coefficients.append(problem.variable(f"coefficients_{foot}", c, scale=1.0)
                            if flags["kinematicsBSplineCoefficients"] else cs.DM(c))
        parts = []
        for a, axis in enumerate(_AXES):
            value = float(state.electrical_center_shifts[i][a])
            parts.append(_scalar(problem, flags[f"electricalCenter{axis.upper()}"], f"ec_{axis}_{foot}", value,
                                 scale=0.01))
        shifts.append(cs.vertcat(*parts))
        rotations.append(_scalar(problem, flags["forcePlateRotation"], f"plate_rotation_{foot}",
                                 float(state.plate_rotations[i]), lower=-PLATE_ROTATION_BOUND,
                                 upper=PLATE_ROTATION_BOUND))
    return Design(k, damping, mu_d, mu_v, rest, cs.DM(state.latching_velocity), coefficients, shifts, rotations)


def build_task_problem(feet: Sequence[FootInputs], state: GcpState, task: GcpTask, terms: Sequence[Term],
                       *, name: str = "gcp_task", lift: bool = True) -> TaskProblem:
    """The task's problem with ``terms`` (registered GCP cost terms) added.

    With ``lift`` and optimized kinematics, each foot's coordinates and rates enter the
    terms through lifted parameters ``q_<foot>``/``qdot_<foot>`` (see :class:`TaskProblem`).
    """
    problem = OptimizationProblem(name)
    design = build_design(problem, state, task.design_flags)
    values = []
    for i, foot in enumerate(feet):
        q, qdot = foot_coordinates(foot, design.coefficients[i])
        if lift and task.design_flags["kinematicsBSplineCoefficients"]:
            numeric = foot_coordinates(foot, cs.DM(state.coefficients[i]))
            coordinates = (problem.lifted_parameter(f"q_{foot.index}", q, np.array(numeric[0])),
                           problem.lifted_parameter(f"qdot_{foot.index}", qdot, np.array(numeric[1])))
            values.append(foot_values(foot, design, i, coordinates=coordinates))
        else:
            values.append(foot_values(foot, design, i, coordinates=(q, qdot)))
    context = GcpContext(feet, values, design, task.neighborStandardDeviation)
    for term in terms:
        problem.add_term(term, context)
    return TaskProblem(problem, context, values, design, list(terms))


#: the back end that solves a task (:mod:`nmsm.core.backends.lifted_least_squares`)
BACKEND = "lifted_least_squares"


def solve_task(task: TaskProblem, **options: Any) -> Solution:
    """Solve a built task with :data:`BACKEND` (``options``: :func:`solver_options`, ``verbose``)."""
    return task.problem.solve(BACKEND, **options)


def solver_options(settings: GroundContactPersonalizationSettings, max_iterations: int | None = None) -> dict[str, Any]:
    """Options of :data:`BACKEND` from the settings (module docstring)."""
    iterations = settings.max_iterations if max_iterations is None else max_iterations
    return {
        "ftol": settings.function_tolerance,
        "xtol": settings.step_tolerance,
        "gtol": settings.optimality_tolerance,
        "max_nfev": int(min(iterations, settings.max_function_evaluations)),
    }


def updated_state(state: GcpState, solution: Solution, n_feet: int) -> GcpState:
    """``state`` with the solved blocks replaced by ``solution``'s values."""
    new = state.copy()
    v = solution.values
    if "spring_constants" in v:
        new.spring_constants = np.asarray(v["spring_constants"], dtype=float).ravel()
    for key, attr in (("damping_factor", "damping_factor"), ("dynamic_friction", "dynamic_friction_coefficient"),
                      ("viscous_friction", "viscous_friction_coefficient"),
                      ("resting_length", "resting_spring_length")):
        if key in v:
            setattr(new, attr, float(np.asarray(v[key]).ravel()[0]))
    for i in range(n_feet):
        foot = i + 1
        if f"coefficients_{foot}" in v:
            new.coefficients[i] = np.asarray(v[f"coefficients_{foot}"], dtype=float)
        for a, axis in enumerate(_AXES):
            if f"ec_{axis}_{foot}" in v:
                new.electrical_center_shifts[i][a] = float(np.asarray(v[f"ec_{axis}_{foot}"]).ravel()[0])
        if f"plate_rotation_{foot}" in v:
            new.plate_rotations[i] = float(np.asarray(v[f"plate_rotation_{foot}"]).ravel()[0])
    return new

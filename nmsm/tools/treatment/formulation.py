"""Assemble a TO/VO/DO optimal control problem (docs/treatment.md, 'Formulation').

Implicit dynamics: states are ``[q_s, q̇_s]`` of the ``states_coordinate_list`` followed
by the controllers' own states (e.g. muscle activations under activation dynamics);
controls are ``[q̈_s, controller controls...]``; the transcription enforces ``d/dt q = q̇``,
``d/dt q̇ = q̈`` and each controller's state dynamics. Physics enters through terms (``kinetic_consistency``:
inverse dynamics = controller loads; ``root_segment_residual_load``). Other coordinates
are prescribed from splines of the tracked kinematics.

Objective: mean of the continuous terms' integrals plus mean of the discrete terms; with
``normalize_cost_by_term_type`` each term's part is divided by the count of its type and the
result averaged over types.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem
from nmsm.core.ocp import evaluation_of
from nmsm.core.term import CostTerm, Term
from nmsm.tools.treatment.context import TreatmentContext
from nmsm.tools.treatment.problem_data import TreatmentData
from nmsm.tools.treatment.quantities import ContextQuantities
from nmsm.core.transcription.base import Block, FinalTime, Phase, Trajectory, Transcription
from nmsm.core.transcription.lgr import RadauCollocation
from nmsm.core.transcription.mesh import Mesh

ACCEL_PREFIX = "accel:"


def speed_label(coordinate: str) -> str:
    """State column of a coordinate's speed (as in the original's ``_states.sto``)."""
    return f"{coordinate}_u"


@attrs.define
class StateSetup:
    """Bounds (2 n_s,) of [q_s, q̇_s] and (n_s,) of q̈_s, and guesses on the mesh."""

    lower: np.ndarray
    upper: np.ndarray
    accel_lower: np.ndarray
    accel_upper: np.ndarray
    guess: np.ndarray  # (K + 1, 2 n_s)
    accel_guess: np.ndarray  # (K, n_s)


@attrs.define
class TreatmentProblem:
    """A built problem: the OptimizationProblem, its trajectory, the terms' context."""

    data: TreatmentData
    problem: OptimizationProblem
    trajectory: Trajectory
    context: TreatmentContext
    terms: list[Term]
    weights: dict[int, float]


def _dynamics(n_s: int, n_u: int, n_p: int, blocks: Sequence[tuple[int, int, cs.Function | None]] = ()) -> cs.Function:
    """Per point ``(x, u, p) -> dx/dt``: ``[q̇_s, q̈_s]`` then each controller's state
    derivatives from its own states and controls; ``blocks``: per controller, in order, its
    state count, control count and state dynamics (their order in ``x`` and ``u``)."""
    n_x = 2 * n_s + sum(n_cx for n_cx, _, _ in blocks)
    x = cs.SX.sym("x", n_x)
    u = cs.SX.sym("u", n_u)
    p = cs.SX.sym("p", n_p)
    parts = [x[n_s:2 * n_s], u[:n_s]]
    x_at, u_at = 2 * n_s, n_s
    for n_cx, n_cu, dynamics in blocks:
        if n_cx:
            (derivative,) = dynamics.call([x[x_at:x_at + n_cx], u[u_at:u_at + n_cu]])
            parts.append(derivative)
        x_at, u_at = x_at + n_cx, u_at + n_cu
    return cs.Function("implicit_kinematics", [x, u, p], [cs.vertcat(*parts)])


def term_weights(terms: Sequence[Term], by_type: bool) -> dict[int, float]:
    """Objective weight of each cost term (keyed by ``id(term)``), see module docstring."""
    costs = [t for t in terms if isinstance(t, CostTerm)]
    weights: dict[int, float] = {}
    for discrete in (False, True):
        group = [t for t in costs if (evaluation_of(t) == "discrete") == discrete]
        if not group:
            continue
        if by_type:
            counts = Counter(t.type for t in group)
            n_types = len(counts)
            for t in group:
                weights[id(t)] = 1.0 / (counts[t.type] * n_types)
        else:
            for t in group:
                weights[id(t)] = 1.0 / len(group)
    return weights


def build_problem(
    data: TreatmentData,
    mesh: Mesh,
    states: StateSetup,
    terms: Sequence[Term],
    *,
    name: str = "treatment",
    transcription: Transcription | None = None,
    normalize_cost_by_term_type: bool = False,
    parallel: int = 1,
    declare_extra: Any = None,
) -> TreatmentProblem:
    """Declare variables, defects, controller parameters and terms in a new problem.

    ``declare_extra(problem, data)`` (optional) declares static design variables before the
    context is built (DO parameters); it must put them in ``data.parameters``.
    """
    problem = OptimizationProblem(name)
    sc = data.state_coordinates
    n_s = len(sc)
    own = [(list(c.state_specs()), list(c.control_specs())) for c in data.controllers]
    blocks = [(len(x), len(u), c.state_dynamics() if x else None) for c, (x, u) in zip(data.controllers, own)]
    state_specs = [spec for x, _ in own for spec in x]
    state_names = tuple(sc) + tuple(speed_label(c) for c in sc) + tuple(s.name for s in state_specs)
    control_specs = [spec for _, u in own for spec in u]
    control_names = tuple(f"{ACCEL_PREFIX}{c}" for c in sc) + tuple(s.name for s in control_specs)
    K = mesh.n_collocation
    c_lower = np.concatenate([states.accel_lower, [s.lower for s in control_specs]])
    c_upper = np.concatenate([states.accel_upper, [s.upper for s in control_specs]])
    c_guess = np.hstack([states.accel_guess.reshape(K, n_s)] +
                        [np.asarray(s.guess, dtype=float).reshape(K, 1) for s in control_specs])
    c_scale = None
    c_offset = None
    if any(s.scale is not None or s.offset is not None for s in control_specs):
        def _default_scale(lo: float, hi: float) -> float:
            return hi - lo if np.isfinite(lo) and np.isfinite(hi) and hi > lo else 1.0

        def _default_offset(lo: float, hi: float) -> float:
            return 0.5 * (hi + lo) if np.isfinite(lo) and np.isfinite(hi) and hi > lo else 0.0

        c_scale = np.array([_default_scale(lo, hi) for lo, hi in zip(c_lower, c_upper)])
        c_offset = np.array([_default_offset(lo, hi) for lo, hi in zip(c_lower, c_upper)])
        for j, s in enumerate(control_specs, start=n_s):
            if s.scale is not None:
                c_scale[j] = s.scale
            if s.offset is not None:
                c_offset[j] = s.offset
    lo_t, hi_t = data.final_time_bounds
    phase = Phase(
        mesh=mesh,
        states=Block(state_names, np.r_[states.lower, [s.lower for s in state_specs]],
                     np.r_[states.upper, [s.upper for s in state_specs]],
                     np.hstack([states.guess.reshape(mesh.n_nodes, 2 * n_s)] +
                               [np.asarray(s.guess, dtype=float).reshape(mesh.n_nodes, 1) for s in state_specs])),
        controls=Block(control_names, c_lower, c_upper, c_guess, c_scale, c_offset),
        dynamics=_dynamics(n_s, len(control_names), 0, blocks),
        final_time=FinalTime(data.final_time_guess, lo_t, hi_t),
    )
    transcription = transcription or RadauCollocation(parallel=parallel)
    trajectory = transcription.transcribe(phase, problem)
    data.acceleration_control_offset = 0
    for controller in data.controllers:
        controller.declare(problem)
    if declare_extra is not None:
        declare_extra(problem, data)
    context = TreatmentContext(ContextQuantities(data, trajectory, parallel=parallel))
    weights = term_weights(terms, normalize_cost_by_term_type)
    for term in terms:
        problem.add_term(term, context, weight=weights.get(id(term), 1.0))
    return TreatmentProblem(data, problem, trajectory, context, list(terms), weights)

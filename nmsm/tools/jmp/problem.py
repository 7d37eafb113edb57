"""One JMP task as a single least-squares problem over every frame's coordinates and the
model parameters.

Minimizing the marker errors over the free coordinates of all ``F`` frames ``q_f`` and the
design parameters ``p`` together is minimizing, over ``p``, the errors left after inverse
kinematics with the model ``p`` describes (the original's nested IK), without an inner
solver and without finite differences: the Jacobian is exact and has a block-arrow
structure (frame ``f``'s residuals depend on ``q_f`` and ``p`` only) that the Schur
complement solves in time linear in ``F``
(:class:`~nmsm.core.jacobians.BlockArrowJacobian`). :class:`JmpProblem` states it as a
:class:`~nmsm.core.residual_problem.ResidualProblem`, solved by the back end
``levenberg_marquardt``.

Terms see one frame: :class:`JmpContext` gives the frame's symbolic (SX) quantities and
reduces a term's normalized values by ``1/sqrt(n_observations)``; the per-frame residual
function (with its exact Jacobians) is ``map``-ped over frames. Variable vector:
``x = [q_1, ..., q_F, p]`` (rad / m; scale factors dimensionless).

:meth:`JmpProblem.optimization_problem` states the same problem as a generic
:class:`~nmsm.core.problem.OptimizationProblem` (for the generic back ends; used to
cross-check the solver).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.backends.base import get_backend
from nmsm.core.backends.levenberg_marquardt import Tolerances
from nmsm.core.convergence import ConvergenceHistory
from nmsm.core.jacobians import BlockArrowJacobian
from nmsm.core.problem import OptimizationProblem
from nmsm.core.residual_problem import ResidualProblem
from nmsm.core.term import CostTerm
from nmsm.core.threads import SOLVER_THREADS, thread_map
from nmsm.tools.jmp.dense_evaluator import DenseEvaluator
from nmsm.tools.jmp.marker_data import MarkerTrial
from nmsm.tools.jmp.marker_model import MarkerKinematics


@attrs.define(eq=False)
class JmpContext:
    """One frame of a JMP task, symbolically: what JMP cost terms read.

    ``q`` (n_free), ``p`` (k): the frame's free coordinates and the design parameters;
    ``x_exp`` (3M, xyz per marker, m) and ``sqrt_w`` (M, 0 in gaps): the frame's data.
    """

    kinematics: MarkerKinematics
    x_exp: cs.SX
    sqrt_w: cs.SX
    n_observations: int
    tool: str = "JMP"

    @property
    def q(self) -> cs.SX:
        return self.kinematics.q

    @property
    def p(self) -> cs.SX:
        return self.kinematics.p

    def marker_position_errors(self) -> cs.SX:
        """``sqrt(w_m) (x_m(q, p) - x_m,exp)`` stacked marker by marker (3M, m)."""
        weights = cs.vec(cs.repmat(cs.transpose(self.sqrt_w), 3, 1))
        return (cs.vec(self.kinematics.positions) - self.x_exp) * weights

    def reduce_cost(self, term: Any, normalized: Any) -> Any:
        """Mean over the task's marker observations: ``z / sqrt(n_observations)``."""
        return cs.vec(normalized) / np.sqrt(max(self.n_observations, 1))


@attrs.frozen
class JmpSolution:
    """Solved task: ``q`` ``(F, n_free)``, ``p`` ``(k,)``; ``cost`` = sum of squared residuals;
    ``term_costs`` per term label; solver outcome."""

    q: np.ndarray
    p: np.ndarray
    cost: float
    initial_cost: float
    term_costs: dict[str, float]
    converged: bool
    status: str
    iterations: int
    evaluations: int
    wall_time: float
    reseated_frames: int = 0
    history: ConvergenceHistory | None = None


class JmpProblem(ResidualProblem):
    """The least-squares problem of one task (see module docstring)."""

    name = "jmp"

    def __init__(self, kinematics: MarkerKinematics, trial: MarkerTrial, terms: Sequence[CostTerm],
                 p_lower: np.ndarray, p_upper: np.ndarray, *, workers: int = SOLVER_THREADS) -> None:
        if tuple(trial.names) != kinematics.marker_names:
            raise ValueError("the trial's markers and the kinematics' markers differ")
        self.kinematics = kinematics
        self.trial = trial
        self.terms = list(terms)
        self.p_lower = np.asarray(p_lower, dtype=float)
        self.p_upper = np.asarray(p_upper, dtype=float)
        n_markers = kinematics.n_markers
        self.context = JmpContext(kinematics, cs.SX.sym("x_exp", 3 * n_markers), cs.SX.sym("sqrt_w", n_markers),
                                  int(trial.present.sum()))
        parts = []
        for term in self.terms:
            term.bind(self.context)
            parts.append(cs.SX(term.residuals(self.context)))
        r = cs.vertcat(*parts)
        inputs = [kinematics.q, kinematics.p, self.context.x_exp, self.context.sqrt_w]
        frame = cs.Function("jmp_frame", inputs, [r, cs.jacobian(r, kinematics.q), cs.jacobian(r, kinematics.p)])
        costs = cs.Function("jmp_frame_costs", inputs, [cs.vertcat(*[cs.sumsqr(part) for part in parts])])
        n = trial.n_frames
        self.n_residuals = int(r.numel())
        self._frame = frame
        # p (input 1) is shared by all frames
        self._mapped = DenseEvaluator(thread_map(frame, n, shared=(1,), threads=workers, name="jmp_frames"))
        self._costs = DenseEvaluator(thread_map(costs, n, shared=(1,), threads=workers, name="jmp_frame_costs"))
        # column-major inputs: frame after frame (see DenseEvaluator)
        self._x_exp = trial.filled_positions().reshape(n, -1)  # (F, 3M)
        self._sqrt_w = trial.sqrt_weights()  # (F, M)

    @property
    def n_frames(self) -> int:
        return self.trial.n_frames

    @property
    def n_free(self) -> int:
        return self.kinematics.n_free

    @property
    def n_parameters(self) -> int:
        return int(self.p_lower.size)

    def pack(self, q: np.ndarray, p: np.ndarray) -> np.ndarray:
        return np.concatenate([np.asarray(q, dtype=float).reshape(-1), np.asarray(p, dtype=float).reshape(-1)])

    def unpack(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        split = self.n_frames * self.n_free
        return x[:split].reshape(self.n_frames, self.n_free), x[split:]

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lower = self.pack(np.tile(self.kinematics.lower, (self.n_frames, 1)), self.p_lower)
        upper = self.pack(np.tile(self.kinematics.upper, (self.n_frames, 1)), self.p_upper)
        return lower, upper

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, BlockArrowJacobian]:
        """Residuals (frame after frame) and their Jacobian at ``x``."""
        q, p = self.unpack(x)
        r, dq, dp = self._mapped(q, p, self._x_exp, self._sqrt_w)
        n, m = self.n_frames, self.n_residuals
        r = r.T.reshape(-1)
        dq = dq.reshape(m, n, self.n_free).transpose(1, 0, 2)
        dp = dp.reshape(m, n, self.n_parameters).transpose(1, 0, 2)
        return r, BlockArrowJacobian(dq, dp)

    def frame_costs(self, q: np.ndarray, p: np.ndarray) -> np.ndarray:
        """Sum of squared residuals of each frame ``(F,)`` at coordinates ``q`` ``(F, n_free)``."""
        return np.asarray(self._costs(q, p, self._x_exp, self._sqrt_w)[0]).sum(axis=0)

    def term_costs(self, q: np.ndarray, p: np.ndarray) -> dict[str, float]:
        """Objective contribution of each term (sum over frames)."""
        values = self._costs(q, p, self._x_exp, self._sqrt_w)[0].sum(axis=1)
        out: dict[str, float] = {}
        for term, value in zip(self.terms, values):
            key, k = term.label, 2
            while key in out:
                key, k = f"{term.label}#{k}", k + 1
            out[key] = float(value)
        return out

    def values(self, x: np.ndarray) -> dict[str, np.ndarray]:
        """``q`` ``(F, n_free)`` and ``p`` ``(k,)`` of ``x``."""
        q, p = self.unpack(x)
        return {"q": q, "p": p}

    def costs(self, x: np.ndarray) -> dict[str, float]:
        return self.term_costs(*self.unpack(x))

    def solve(self, q0: np.ndarray, p0: np.ndarray, tolerances: Tolerances = Tolerances(), *,
              callback: Callable[[int, float, np.ndarray], None] | None = None,
              backend: str = "levenberg_marquardt") -> JmpSolution:
        """Solve from coordinates ``q0`` ``(F, n_free)`` and parameters ``p0`` ``(k,)`` with the
        back end ``backend`` (one that takes a :class:`~nmsm.core.residual_problem.ResidualProblem`
        and the :class:`~nmsm.core.backends.levenberg_marquardt.Tolerances` as options)."""
        lower, upper = self.bounds()
        x0 = np.clip(self.pack(q0, p0), lower, upper)
        r0, _ = self.evaluate(x0)
        solution = get_backend(backend).solve(self, initial_guess=x0, callback=callback, **attrs.asdict(tolerances))
        return JmpSolution(q=solution.values["q"], p=solution.values["p"], cost=solution.cost,
                           initial_cost=float(r0 @ r0), term_costs=solution.term_costs, converged=solution.success,
                           status=solution.status, iterations=solution.iterations,
                           evaluations=int(solution.evaluations or 0), wall_time=solution.wall_time,
                           history=solution.history)

    def optimization_problem(self, q0: np.ndarray, p0: np.ndarray) -> OptimizationProblem:
        """The same problem as a generic :class:`OptimizationProblem` (variables ``q``
        ``(n_free, F)`` and ``p`` ``(k, 1)``; residuals frame after frame)."""
        problem = OptimizationProblem("jmp")
        kin = self.kinematics
        n = self.n_frames
        q = problem.variable("q", np.asarray(q0).T, np.tile(kin.lower[:, None], (1, n)),
                             np.tile(kin.upper[:, None], (1, n)), scale=1.0, shape=(kin.n_free, n))
        p = problem.variable("p", p0, self.p_lower, self.p_upper, scale=1.0, shape=(self.n_parameters, 1))
        x_exp = problem.parameter("x_exp", self._x_exp.T)
        sqrt_w = problem.parameter("sqrt_w", self._sqrt_w.T)
        r = self._frame.map(n, "thread", SOLVER_THREADS)(q, p, x_exp, sqrt_w)[0]
        problem.add_cost("jmp", r)
        return problem

"""The NCP optimization problem: synergy variables, terms, weight-sum constraints.

Design variables (all >= 0, no upper bounds; docs/ncp.md):

* ``weights_<group>`` (S_g, M_g) for each group whose vectors are free (a group sharing
  another's vectors under bilateral symmetry has none);
* ``nodes_<trial>`` (N, S): command spline nodes of every synergy in the trial.

Activations ``a_t = (B @ nodes_t) @ W`` are bilinear in the variables and moments linear in
activations, so the objective is a quartic polynomial; its exact Hessian is assembled from
that structure (:meth:`NcpProblem.ipopt_options`, :mod:`nmsm.tools.ncp.hessian`).
Each free group's vectors sum to ``M_g/100`` (the registered constraint ``synergy_weight_sum``).

Proximal term: with the settings' terms alone the activations can be undetermined (e.g.
moment tracking only: infinitely many synergy sets give the same moments) and an
optimizer then drifts anywhere along that set. ``proximal_weight`` (default
:data:`PROXIMAL_WEIGHT`) adds ``w * mean((a - a_start)**2)`` over all activations, pulling
toward the starting activations (the NMF of the MTP activations). It selects a solution
where the settings' terms are flat and is negligible elsewhere (w = 0.1 is a term with
``max_allowable_error`` ≈ 3.2 activation units); it is reported as its own entry
(``proximal:start_activations``) and never counted in NCP's cost. Use 0 to drop it.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.registry import get_registry
from nmsm.core.term import CostTerm, Term
from nmsm.tools.ncp.context import NcpContext
from nmsm.tools.ncp.initial_guess import SynergyGuess
from nmsm.tools.ncp.inputs import NcpInputs
from nmsm.tools.ncp.solution import SynergySolution
from nmsm.tools.ncp.synergies import activations as synergy_activations


#: weight of the proximal term toward the starting activations (see module docstring)
PROXIMAL_WEIGHT = 0.1
#: name of the proximal cost entry
PROXIMAL_ENTRY = "proximal:start_activations"


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c == "_" else "_" for c in name)


def _scale(values: np.ndarray, floor: float) -> float:
    positive = np.asarray(values)[np.asarray(values) > 0]
    return float(max(positive.mean() if positive.size else 0.0, floor))


@attrs.define
class NcpProblem:
    """The built problem, its context and the names of its variables."""

    inputs: NcpInputs
    problem: OptimizationProblem
    context: NcpContext
    weight_variables: list[str]
    node_variables: list[str]
    #: every cost entry as (weight, residual builder taking an NcpContext), for the structured Hessian
    cost_builders: list[tuple[float, Callable[[NcpContext], Any]]] = attrs.field(factory=list)
    _hessian: Any = attrs.field(default=None, init=False)

    def ipopt_options(self) -> dict[str, Any]:
        """Back-end options giving IPOPT the structured exact Hessian (:mod:`nmsm.tools.ncp.hessian`).

        Empty when the terms do not have the affine frame-local form (CasADi's automatic
        Hessian is used then, much slower to build for large models).
        """
        from nmsm.tools.ncp.hessian import hessian_function

        function = hessian_function(self.problem, self.inputs, self.cost_builders, self.weight_variables, self.node_variables)
        if function is None:
            warnings.warn(
                "NCP: a cost term is not affine in the activations frame by frame; using CasADi's automatic "
                "Hessian (slow to build for large models)",
                stacklevel=2,
            )
            return {}
        self._hessian = function  # the callback must outlive the solver
        return {"casadi_options": {"hess_lag": function}}

    def solution(self, solved: Solution) -> SynergySolution:
        """The synergies (not normalized) at a solved point."""
        return self.synergies_from_values(solved.values)

    def synergies_from_values(self, values: dict[str, np.ndarray]) -> SynergySolution:
        layout = self.inputs.layout
        blocks = [np.asarray(values[name]) for name in self.weight_variables]
        weights = layout.weight_matrix(blocks)
        nodes = [np.asarray(values[name]) for name in self.node_variables]
        commands = [layout.commands(n, t.n_points) for n, t in zip(nodes, self.inputs.trials)]
        return SynergySolution(
            layout=layout,
            weights=weights,
            commands=commands,
            nodes=nodes,
            trial_names=[t.name for t in self.inputs.trials],
        )


def build_problem(
    inputs: NcpInputs,
    terms: Sequence[Term],
    guess: SynergyGuess,
    *,
    name: str = "ncp",
    proximal_weight: float = PROXIMAL_WEIGHT,
) -> NcpProblem:
    """Declare the variables, add ``terms``, the weight-sum constraints and the proximal term
    (see module docstring)."""
    layout = inputs.layout
    problem = OptimizationProblem(name)
    weight_names: list[str] = []
    free_blocks: list[Any] = []
    for block_index, group in enumerate(layout.free_groups):
        g = layout.groups[group]
        var = f"weights_{_safe(g.name)}"
        initial = guess.weight_blocks[block_index]
        expr = problem.variable(var, initial, lower=0.0, upper=np.inf, scale=g.weight_sum / g.n_muscles)
        weight_names.append(var)
        free_blocks.append(expr)
    weight_blocks = layout.group_blocks(free_blocks)
    weights = layout.weight_matrix(free_blocks)
    node_names: list[str] = []
    activations = []
    for t, trial in enumerate(inputs.trials):
        var = f"nodes_{_safe(trial.name)}_{t}"
        initial = guess.nodes[t]
        nodes = problem.variable(var, initial, lower=0.0, upper=np.inf, scale=_scale(initial, 1e-2))
        node_names.append(var)
        activations.append(synergy_activations(weights, layout.commands(nodes, trial.n_points)))
    context = NcpContext(inputs, weight_blocks, activations)
    builders: list[tuple[float, Callable[[NcpContext], Any]]] = []
    for term in terms:
        problem.add_term(term, context)
        if isinstance(term, CostTerm):
            builders.append((1.0, term.residuals))
    if proximal_weight > 0:
        start_weights = layout.weight_matrix(list(guess.weight_blocks))
        starts = [layout.commands(guess.nodes[t], trial.n_points) @ start_weights for t, trial in enumerate(inputs.trials)]

        def proximal(ctx: NcpContext, starts: list[np.ndarray] = starts) -> Any:
            stacked = cs.vertcat(*[cs.vec(a - cs.DM(s0)) for a, s0 in zip(ctx.activations, starts)])
            return stacked / np.sqrt(stacked.numel())

        problem.add_cost(PROXIMAL_ENTRY, proximal(context), weight=proximal_weight)
        builders.append((proximal_weight, proximal))
    weight_sum = get_registry().get("constraint", "synergy_weight_sum", "NCP")
    for group in layout.free_groups:
        g = layout.groups[group]
        problem.add_term(weight_sum(group=group, target=g.weight_sum, name=g.name), context)
    return NcpProblem(inputs, problem, context, weight_names, node_names, builders)


def score(inputs: NcpInputs, terms: Sequence[Term], solution: SynergySolution) -> dict[str, float]:
    """Each cost term's value (and ``total``) for a given solution, evaluated with numpy."""
    blocks = [solution.group_weights(g) for g in range(len(inputs.layout.groups))]
    context = NcpContext(inputs, blocks, solution.all_activations())
    out: dict[str, float] = {}
    for term in terms:
        if getattr(term, "kind", "") != "cost":
            continue
        residuals = np.asarray(term.residuals(context), dtype=float)
        key = term.label
        k = 2
        while key in out:
            key = f"{term.label}#{k}"
            k += 1
        out[key] = float(np.sum(residuals**2))
    out["total"] = float(sum(out.values()))
    return out

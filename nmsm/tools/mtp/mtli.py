"""Muscle-Tendon Length Initialization (MTLI): least-squares fit of l_o, l_ts (and stress).

Runs before MTP (and NCP) when enabled (docs/mtp.md). Residual vector of the enabled
terms, each ``(x - c) / (e sqrt(n))``; the original uses ``lsqnonlin`` (100 iterations).
Here IPOPT minimizes the same sum of squares within the bounds with exact gradients and a
Gauss-Newton Hessian (:func:`nmsm.tools.mtp.derivatives.gauss_newton_hessian`): scipy's
least-squares needs an SVD of the (residuals x variables) Jacobian per iteration, which
grows with the muscles and frames (docs/developing.md, "MTP: measurements").
Result: new optimal fiber lengths, tendon slack lengths and (with
``optimize_isometric_max_force``) maximum isometric forces ``F0 = V / l_o * sigma0 * s_sigma``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import casadi as cs
import numpy as np

from nmsm.core.problem import OptimizationProblem, Solution
from nmsm.core.term import CostTerm
from nmsm.errors import InputError
from nmsm.io.storage import read_storage
from nmsm.io.trials import find_file_by_suffix, find_trial_file, find_trial_folder
from nmsm.tools.mtp.data import check_same_times, find_prefixes, read_moment_arms
from nmsm.tools.mtp.derivatives import gauss_newton_hessian
from nmsm.tools.mtp.mtli_model import MtliContext, PassiveTrial, max_length_variable_index, mtli_quantities
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters

SCALE_BOUNDS = (0.5, 2.0)
ABSOLUTE_BOUNDS = (0.001, 2.0)
MAX_LENGTH_BOUNDS = (1.0, 1.2)
STRESS_BOUNDS = (0.6, 2.3)


@attrs.frozen
class MtliOptions:
    """MTLI settings (SI). ``max_/min_normalized_fiber_length`` feed the fiber-length terms."""

    max_normalized_fiber_length: float = 1.0
    min_normalized_fiber_length: float = 0.6
    optimize_maximum_muscle_stress: bool = False
    update_max_isometric_force: bool = True
    absolute_lengths: bool = False
    maximum_muscle_stress: float = 610_000.0
    max_iterations: int = 100


@attrs.frozen(eq=False)
class MtliResult:
    """Updated muscle parameters and the fit's details."""

    muscles: MuscleParameters
    optimal_fiber_length_scale: np.ndarray
    tendon_slack_length_scale: np.ndarray
    stress_scale: float
    max_normalized_length: np.ndarray
    solution: Solution
    passive_moments: list[np.ndarray]


def load_passive_trials(
    directory: str | os.PathLike[str], coordinates: Sequence[str], muscles: Sequence[str]
) -> tuple[PassiveTrial, ...]:
    """Passive trials: ``IDData/<trial>`` (N m) and ``MAData/<trial>/`` lengths and moment arms."""
    root = Path(directory)
    trials = []
    for prefix in find_prefixes(root):
        table = read_storage(find_trial_file(root / "IDData", prefix))
        moments = np.column_stack([table.load_column(c) for c in coordinates])
        folder = find_trial_folder(root / "MAData", prefix)
        length = read_storage(find_file_by_suffix(folder, "_Length"))
        missing = [m for m in muscles if not length.has(m)]
        if missing:
            raise InputError(
                f"passive trial '{prefix}': no length column for {', '.join(missing)}",
                file=length.source,
                expected="a column per muscle crossing <coordinate_list>",
            )
        lmt = length.columns(muscles)
        arms = read_moment_arms(folder, prefix, coordinates, muscles, reference=table)
        if not (lmt.shape[0] == arms.shape[0] == moments.shape[0]):
            raise InputError(
                f"passive trial '{prefix}': ID has {moments.shape[0]} rows, lengths {lmt.shape[0]}, moment arms {arms.shape[0]}",
                file=folder,
                expected="IDData and MAData sampled at the same frames",
            )
        check_same_times(table, length, prefix)
        trials.append(PassiveTrial(prefix, table.time, lmt, arms, moments))
    return tuple(trials)


def build_mtli_problem(
    muscles: MuscleParameters,
    gait_lengths: Sequence[np.ndarray],
    passive_trials: Sequence[PassiveTrial],
    groups: Sequence[MuscleGroup],
    terms: Sequence[CostTerm],
    options: MtliOptions,
) -> tuple[OptimizationProblem, MtliContext]:
    """The MTLI least-squares problem and its term context."""
    problem = OptimizationProblem("MTLI")
    m = muscles.n_muscles
    if options.absolute_lengths:
        lo = problem.variable("optimal_fiber_length", muscles.optimal_fiber_length, *ABSOLUTE_BOUNDS)
        lts = problem.variable("tendon_slack_length", muscles.tendon_slack_length, *ABSOLUTE_BOUNDS)
    else:
        lo = problem.variable("optimal_fiber_length_scale", np.ones(m), *SCALE_BOUNDS)
        lts = problem.variable("tendon_slack_length_scale", np.ones(m), *SCALE_BOUNDS)
    index = max_length_variable_index(m, groups)
    n_vars = int(index.max()) + 1 if m else 0
    max_len = problem.variable("max_normalized_length", np.ones(n_vars), *MAX_LENGTH_BOUNDS)
    stress = problem.variable("stress_scale", [1.0], *STRESS_BOUNDS) if options.optimize_maximum_muscle_stress else cs.MX(1.0)
    _, fiber, passive, moments = mtli_quantities(
        muscles,
        gait_lengths,
        passive_trials,
        optimal_fiber_length=lo,
        tendon_slack_length=lts,
        stress_scale=stress,
        absolute_lengths=options.absolute_lengths,
        update_max_isometric_force=options.update_max_isometric_force,
        maximum_muscle_stress=options.maximum_muscle_stress,
    )
    ctx = MtliContext(
        muscles=muscles,
        absolute_lengths=options.absolute_lengths,
        optimal_fiber_length_variable=lo,
        tendon_slack_length_variable=lts,
        max_normalized_length=max_len,
        stress_scale=stress,
        variable_of_muscle=index,
        fiber_length=fiber,
        passive_force=passive,
        passive_moments=moments,
        passive_trials=tuple(passive_trials),
        fiber_length_groups=tuple(groups),
        min_normalized_fiber_length=options.min_normalized_fiber_length,
        max_normalized_fiber_length=options.max_normalized_fiber_length,
    )
    for term in terms:
        problem.add_term(term, ctx)
    return problem, ctx


def run_mtli(
    muscles: MuscleParameters,
    gait_lengths: Sequence[np.ndarray],
    passive_trials: Sequence[PassiveTrial],
    groups: Sequence[MuscleGroup],
    terms: Sequence[CostTerm],
    options: MtliOptions,
) -> MtliResult:
    """Solve MTLI and return the updated muscle parameters."""
    problem, ctx = build_mtli_problem(muscles, gait_lengths, passive_trials, groups, terms, options)
    solution = problem.solve(
        "ipopt",
        max_iter=max(1, options.max_iterations),
        print_level=0,
        casadi_options=gauss_newton_hessian(problem),
    )
    v = solution.values
    if options.absolute_lengths:
        lo = v["optimal_fiber_length"].ravel()
        lts = v["tendon_slack_length"].ravel()
    else:
        lo = muscles.optimal_fiber_length * v["optimal_fiber_length_scale"].ravel()
        lts = muscles.tendon_slack_length * v["tendon_slack_length_scale"].ravel()
    stress = float(v["stress_scale"].ravel()[0]) if "stress_scale" in v else 1.0
    if options.update_max_isometric_force:
        volume = muscles.max_isometric_force * muscles.optimal_fiber_length / options.maximum_muscle_stress
        f0 = volume / lo * options.maximum_muscle_stress * stress
    else:
        f0 = muscles.max_isometric_force
    updated = MuscleParameters(muscles.names, f0, lo, lts, muscles.pennation_angle)
    passive = [problem.evaluate(mom, solution.x_scaled) for mom in ctx.passive_moments]
    return MtliResult(
        muscles=updated,
        optimal_fiber_length_scale=lo / muscles.optimal_fiber_length,
        tendon_slack_length_scale=lts / muscles.tendon_slack_length,
        stress_scale=stress,
        max_normalized_length=v["max_normalized_length"].ravel(),
        solution=solution,
        passive_moments=passive,
    )


def passive_moments_at(muscles: MuscleParameters, passive_trials: Sequence[PassiveTrial]) -> list[np.ndarray]:
    """Passive joint moments (n, C) N m of each passive trial for fixed parameters."""
    _, _, _, moments = mtli_quantities(
        muscles, [], passive_trials,
        optimal_fiber_length=np.ones(muscles.n_muscles), tendon_slack_length=np.ones(muscles.n_muscles),
        stress_scale=1.0, absolute_lengths=False, update_max_isometric_force=False, maximum_muscle_stress=1.0,
    )
    if not moments:
        return []
    values = cs.Function("passive_moments", [], moments).call([])
    return [np.array(v.full()) for v in values]

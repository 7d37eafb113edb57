"""A known-answer Muscle-Tendon Personalization case generated in code.

:func:`make_synthetic_mtp` builds, without any file or model, an
:class:`~nmsm.tools.mtp.problem.MtpData` with

* ``n_muscles`` muscles crossing as many coordinates (well-conditioned moment arms
  around ``diag(+-4 cm)``), one EMG channel per muscle;
* ``n_trials`` trials of 101 frames at 100 Hz with 20 padding frames of EMG each side;
  EMG = smooth bursts in [0, 1];
* muscle-tendon lengths chosen so the *true* normalized fiber lengths swing between
  about 0.75 and 1.15 (and velocities as their exact derivative);
* inverse-dynamics moments = the model's moments at the true parameters (no noise).

The base model the optimizer starts from has l_o, l_ts off by the true scale factors, and
MTP starts at the original's initial values. :func:`recover` runs one MTP task that
tracks the moments and returns the estimate; :data:`TOLERANCES` are the recovery
tolerances the tests hold it to.

Units: m, m/s, N, N m, s; design variables in MTP units (delay 0.1 s, time constant 0.01 s).
"""

from __future__ import annotations

import attrs
import numpy as np

from nmsm.tools.mtp.data import TrialData
from nmsm.tools.mtp.evaluation import evaluate, initial_fiber_lengths
from nmsm.tools.mtp.model import MuscleDesign
from nmsm.tools.mtp.muscles import MuscleParameters
from nmsm.tools.mtp.problem import (
    MtpData,
    MtpState,
    TaskSettings,
    build_task_problem,
    solve_task_problem,
    updated_state,
)

#: recovery tolerances (absolute, in each block's units) of :func:`recover`: the data are
#: exact and the parameters identifiable (as many coordinates as muscles), so IPOPT with
#: exact derivatives recovers them to ~1e-12; 1e-6 leaves room for other platforms.
TOLERANCES = {
    "electromechanical_delay": 1e-6,
    "activation_time_constant": 1e-6,
    "activation_nonlinearity": 1e-6,
    "emg_scale": 1e-6,
    "optimal_fiber_length_scale": 1e-6,
    "tendon_slack_length_scale": 1e-6,
}


@attrs.frozen(eq=False)
class SyntheticMtp:
    """The case: data (with the *base* muscle lengths), the truth, and the true lengths."""

    data: MtpData
    truth: MtpState
    true_muscles: MuscleParameters


def _bursts(time: np.ndarray, centres: np.ndarray, widths: np.ndarray, heights: np.ndarray) -> np.ndarray:
    x = np.zeros_like(time)
    for c, w, h in zip(centres, widths, heights):
        x += h * np.exp(-0.5 * ((time - c) / w) ** 2)
    return np.clip(x, 0.0, 1.0)


def make_synthetic_mtp(n_muscles: int = 3, n_trials: int = 2, seed: int = 3) -> SyntheticMtp:
    """The known-answer case (see the module docstring)."""
    rng = np.random.default_rng(seed)
    m = n_muscles
    names = tuple(f"muscle_{i}" for i in range(m))
    f0 = rng.uniform(800.0, 2500.0, m)
    lo_true = rng.uniform(0.07, 0.13, m)
    lts_true = rng.uniform(0.18, 0.32, m)
    alpha = rng.uniform(0.02, 0.25, m)
    true_muscles = MuscleParameters(names, f0, lo_true, lts_true, alpha)
    truth_design = MuscleDesign(
        electromechanical_delay=rng.uniform(0.3, 0.9, m),
        activation_time_constant=rng.uniform(1.0, 2.5, m),
        activation_nonlinearity=rng.uniform(0.05, 0.25, m),
        emg_scale=rng.uniform(0.3, 0.8, m),
        optimal_fiber_length_scale=rng.uniform(0.9, 1.1, m),
        tendon_slack_length_scale=rng.uniform(0.95, 1.05, m),
    )
    base = MuscleParameters(
        names, f0,
        lo_true / truth_design.optimal_fiber_length_scale,
        lts_true / truth_design.tendon_slack_length_scale,
        alpha,
    )
    n, pad, dt = 101, 20, 0.01
    trials = []
    for k in range(n_trials):
        t0 = 1.0 * k
        emg_time = t0 + dt * np.arange(n + 2 * pad)
        time = emg_time[pad : pad + n]
        emg = np.column_stack([
            _bursts(emg_time, t0 + rng.uniform(0.2, 1.2, 2), rng.uniform(0.06, 0.15, 2), rng.uniform(0.3, 1.0, 2))
            for _ in range(m)
        ])
        phase = rng.uniform(0, 2 * np.pi, m)
        period = time[-1] - time[0]
        target = 0.95 + 0.2 * np.sin(2 * np.pi * (time[:, None] - time[0]) / period + phase)
        dtarget = 0.2 * 2 * np.pi / period * np.cos(2 * np.pi * (time[:, None] - time[0]) / period + phase)
        cos_alpha = np.cos(alpha)
        lmt = lts_true + lo_true * cos_alpha * target
        vmt = lo_true * cos_alpha * dtarget
        signs = np.where(rng.random(m) < 0.5, -1.0, 1.0)
        base_arms = np.diag(0.04 * signs) + 0.01 * rng.standard_normal((m, m))
        arms = base_arms[None] * (1 + 0.1 * np.sin(2 * np.pi * (time[:, None, None] - time[0]) / period))
        trials.append(TrialData(f"trial_{k + 1}", time, lmt, vmt, arms, np.zeros((n, m)), emg_time, emg, pad))
    coordinates = tuple(f"coordinate_{i}" for i in range(m))
    channels = np.arange(m)
    truth_data = MtpData(true_muscles, coordinates, tuple(trials), channels)
    plain, _ = evaluate(truth_data, MtpState(attrs.evolve(truth_design, optimal_fiber_length_scale=np.ones(m),
                                                         tendon_slack_length_scale=np.ones(m))))
    trials = [attrs.evolve(t, inverse_dynamics_moments=plain.moments[k]) for k, t in enumerate(trials)]
    data = MtpData(base, coordinates, tuple(trials), channels)
    return SyntheticMtp(data, MtpState(truth_design), true_muscles)


def recover(case: SyntheticMtp, *, max_iterations: int = 500) -> tuple[MtpState, float, int]:
    """One MTP task tracking the moments (e = 0.01 N m) from the original's initial values.

    Returns ``(estimate, final cost, iterations)``.
    """
    from nmsm.core.registry import get_registry

    term = get_registry().get("cost", "inverse_dynamics_joint_moment", "MTP")(max_allowable_error=0.01)
    task = TaskSettings(cost_terms=(term,))
    state = MtpState.initial(case.data)
    problem, _ = build_task_problem(case.data, state, task, initial_fiber_lengths(case.data))
    solution = solve_task_problem(problem, max_iterations=max_iterations, tolerance=1e-10)
    return updated_state(state, solution.values), solution.cost, solution.iterations


def recovery_errors(case: SyntheticMtp, estimate: MtpState) -> dict[str, float]:
    """Largest absolute error per design block (block units)."""
    return {
        block: float(np.max(np.abs(np.asarray(getattr(estimate.design, block)) - np.asarray(getattr(case.truth.design, block)))))
        for block in TOLERANCES
    }


__all__ = ["SyntheticMtp", "TOLERANCES", "make_synthetic_mtp", "recover", "recovery_errors"]

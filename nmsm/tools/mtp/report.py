"""Compare an MTP run with the original's (a table like the seed paper's Table 2).

``score_parameters`` evaluates *our* cost function at given parameters (e.g. the
original's ``*_mtp.osimx``): l_o, l_ts become scale factors of the task's base lengths
(the MTLI result), the original's F0 replaces ours, and with synergy extrapolation the
synergy weights (not stored by the original) are optimized with every other parameter
fixed, so the original gets its best possible score. ``moment_rms`` reads any results
folder (ours or the original's). ``comparison_table`` formats rows as Markdown.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage
from nmsm.tools.mtp.evaluation import initial_fiber_lengths
from nmsm.tools.mtp.model import MuscleDesign
from nmsm.tools.mtp.problem import BLOCKS, MtpData, MtpState, TaskSettings, build_task_problem, solve_task_problem


@attrs.frozen
class Score:
    cost: float
    term_costs: dict[str, float]


def parameters_from_osimx(path: str | os.PathLike[str], data: MtpData) -> tuple[MtpData, MtpState]:
    """Data (F0 from the osimx) and state (scale factors relative to ``data``'s lengths)."""
    osimx = read_osimx(path)
    names = data.muscles.names
    missing = [n for n in names if n not in osimx.muscles]
    if missing:
        raise InputError(f"no RCNLMuscle for {', '.join(missing)}", file=path, element="RCNLMuscleSet",
                         expected="an entry per MTP muscle")
    m = [osimx.muscles[n] for n in names]

    def field(name: str, default: np.ndarray) -> np.ndarray:
        return np.array([getattr(x, name) if getattr(x, name) is not None else d for x, d in zip(m, default)])

    mus = data.muscles
    lo = field("optimal_fiber_length", mus.optimal_fiber_length)
    lts = field("tendon_slack_length", mus.tendon_slack_length)
    f0 = field("max_isometric_force", mus.max_isometric_force)
    init = MuscleDesign.initial(len(names))
    design = MuscleDesign(
        electromechanical_delay=field("electromechanical_delay", init.electromechanical_delay),
        activation_time_constant=field("activation_time_constant", init.activation_time_constant),
        activation_nonlinearity=field("activation_nonlinearity_constant", init.activation_nonlinearity),
        emg_scale=field("emg_scale_factor", init.emg_scale),
        optimal_fiber_length_scale=lo / mus.optimal_fiber_length,
        tendon_slack_length_scale=lts / mus.tendon_slack_length,
    )
    new_data = attrs.evolve(data, muscles=attrs.evolve(mus, max_isometric_force=f0))
    weights = np.zeros(data.synx.n_weights) if data.synx is not None else np.zeros(0)
    return new_data, MtpState(design, weights)


def score_parameters(
    data: MtpData, state: MtpState, task: TaskSettings, initial_lengths: Sequence[np.ndarray] | None = None,
    *, max_iterations: int = 500,
) -> tuple[Score, MtpState]:
    """Our task cost at ``state``; SynX weights optimized (everything else fixed) when SynX is on."""
    fixed = attrs.evolve(task, optimize=dict.fromkeys(BLOCKS, False))
    lengths = initial_lengths if initial_lengths is not None else initial_fiber_lengths(data)
    problem, _ = build_task_problem(data, state, fixed, lengths, name="MTP_score")
    if data.synx is None:
        costs = problem.term_costs(problem.initial_scaled())
        return Score(float(sum(costs.values())), costs), state
    solution = solve_task_problem(problem, max_iterations=max_iterations)
    weights = np.asarray(solution.values["synergy_weights"]).ravel()
    return Score(solution.cost, dict(solution.term_costs)), MtpState(state.design, weights)


def moment_rms(results_dir: str | os.PathLike[str], *, synx: bool = False) -> dict[str, dict[str, float]]:
    """RMS (N m) of model minus inverse-dynamics moments per trial and coordinate of a results folder."""
    folder = Path(results_dir) / "Analysis"
    quantity = "modelJointMomentsSynx" if synx else "modelJointMoments"
    out: dict[str, dict[str, float]] = {}
    for path in sorted((folder / "inverseDynamicsJointMoments").glob("*.sto")):
        trial = path.stem[: -len("_inverseDynamicsJointMoments")]
        measured = read_storage(path)
        model = read_storage(folder / quantity / f"{trial}_{quantity}.sto")
        out[trial] = {c: float(np.sqrt(np.mean((model.column(c) - measured.column(c)) ** 2))) for c in measured.labels}
    return out


def parameters_within_bounds(state: MtpState, *, tolerance: float = 1e-6) -> bool:
    """True when every design block lies in its bounds."""
    for block, (_, low, high) in BLOCKS.items():
        if block.endswith("_scale") and block.startswith(("optimal", "tendon")):
            continue  # absorbed into the lengths after each task
        value = np.asarray(getattr(state.design, block), dtype=float)
        if np.any(value < low - tolerance) or np.any(value > high + tolerance):
            return False
    return True


@attrs.frozen
class ComparisonRow:
    """One settings file: our run against the original's solution."""

    label: str
    cost_ours: float
    cost_original: float
    rms_ours: dict[str, float]
    rms_original: dict[str, float]
    within_bounds: bool
    wall_time: float
    synx: bool

    @property
    def worst_ratio(self) -> float:
        return max(self.rms_ours[c] / self.rms_original[c] for c in self.rms_original if self.rms_original[c] > 0)


def comparison_table(rows: Sequence[ComparisonRow]) -> str:
    """Markdown table: cost (ours / original scored by nmsm), moment RMS per coordinate, bounds, time."""
    coords = list(rows[0].rms_ours) if rows else []
    head = ["settings", "SynX", "cost nmsm", "cost original (scored by nmsm)"]
    head += [f"RMS {c} (N m) nmsm / original" for c in coords]
    head += ["max RMS ratio", "parameters in bounds", "wall time (s)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [r.label, "yes" if r.synx else "no", f"{r.cost_ours:.4f}", f"{r.cost_original:.4f}"]
        cells += [f"{r.rms_ours[c]:.2f} / {r.rms_original[c]:.2f}" for c in coords]
        cells += [f"{r.worst_ratio:.3f}", "yes" if r.within_bounds else "no", f"{r.wall_time:.1f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)

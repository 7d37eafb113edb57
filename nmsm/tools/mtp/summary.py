"""MTP's console summary: the joint-moment fit per coordinate and the parameters at a bound."""

from __future__ import annotations

import numpy as np

from nmsm.tools.mtp.outcome import MtpOutcome
from nmsm.tools.mtp.problem import BLOCKS, MtpState

#: design blocks shown when at a bound: name, factor to the shown unit, unit (the length
#: scales are absorbed into the lengths after each task, so they are not shown)
SHOWN_BLOCKS = {
    "electromechanical_delay": ("electromechanical delay", 100.0, "ms"),
    "activation_time_constant": ("activation time constant", 10.0, "ms"),
    "activation_nonlinearity": ("activation nonlinearity", 1.0, ""),
    "emg_scale": ("EMG scale", 1.0, ""),
}


def parameters_at_bounds(state: MtpState, muscles: tuple[str, ...], *, tolerance: float = 1e-6
                         ) -> dict[tuple[str, str], list[str]]:
    """``(block, "lower" | "upper")`` -> the muscles whose value of that design block ends
    within ``tolerance`` of the block's range from that bound."""
    out: dict[tuple[str, str], list[str]] = {}
    for block in SHOWN_BLOCKS:
        _, low, high = BLOCKS[block]
        values = np.asarray(getattr(state.design, block), dtype=float).ravel()
        close = tolerance * (high - low)
        for side, bound in (("lower", low), ("upper", high)):
            hits = [m for m, v in zip(muscles, values) if abs(v - bound) <= close]
            if hits:
                out[(block, side)] = hits
    return out


def summary_lines(outcome: MtpOutcome) -> list[str]:
    """Solver outcome per task, the joint-moment RMS (N·m) per coordinate over the trials,
    the parameters at a bound, the time."""
    from nmsm.tools.mtp.report import moment_rms

    lines = [f"task {t.index}: {t.status} after {t.iterations} iterations, {t.wall_time:.1f} s; cost {t.cost:.6g}"
             for t in outcome.tasks]
    per_trial = moment_rms(outcome.results_directory)
    coordinates = list(dict.fromkeys(c for values in per_trial.values() for c in values))
    if coordinates:
        lines.append(f"joint moment RMS error (N·m, model vs inverse dynamics, {len(per_trial)} trial(s)):")
        for c in coordinates:
            values = [v[c] for v in per_trial.values() if c in v]
            lines.append(f"  {c:<32s} {np.sqrt(np.mean(np.square(values))):8.3f}")
    names = outcome.data.muscles.names
    at_bounds = parameters_at_bounds(outcome.state, names)
    if not at_bounds:
        lines.append("parameters at a bound: none")
    for (block, side), hits in at_bounds.items():
        label, factor, unit = SHOWN_BLOCKS[block]
        bound = factor * BLOCKS[block][1 if side == "lower" else 2]
        lines.append(f"{label} at its {side} bound {bound:g}{' ' + unit if unit else ''} ({len(hits)} of "
                     f"{len(names)} muscles): {', '.join(hits)}")
    lines.append(f"total time {outcome.wall_time:.1f} s")
    return lines

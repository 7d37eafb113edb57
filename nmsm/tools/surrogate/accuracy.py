"""The held-out accuracy of a fitted surrogate as a text table (``nmsm surrogate`` prints it)."""

from __future__ import annotations

from nmsm.model.surrogate import SurrogateModel


def accuracy_report(model: SurrogateModel) -> str:
    """A table of each muscle's held-out accuracy (mm), worst muscle last line."""
    lines = [f"{'muscle':<16s} {'coords':>6s} {'L rms':>8s} {'L max':>8s} {'r rms':>8s} {'r max':>8s}   (mm, held-out poses)"]
    worst: tuple[float, str] | None = None
    for m in model.muscles:
        a = m.accuracy
        if a is None:
            lines.append(f"{m.muscle:<16s} {len(m.coordinates):>6d}   (no held-out poses)")
            continue
        lines.append(f"{m.muscle:<16s} {len(m.coordinates):>6d} {a.length_rms * 1e3:8.3f} {a.length_max * 1e3:8.3f} "
                     f"{a.worst_moment_arm_rms * 1e3:8.3f} {a.worst_moment_arm_max * 1e3:8.3f}")
        score = max(a.length_rms / 0.5e-3, a.worst_moment_arm_rms / 1e-3)
        if worst is None or score > worst[0]:
            worst = (score, m.muscle)
    if model.excluded_muscles:
        lines.append(f"not modeled (no moment arm > {model.epsilon:g} m): {', '.join(model.excluded_muscles)}")
    if worst is not None:
        lines.append(f"worst muscle: {worst[1]}")
    return "\n".join(lines)


"""Variable bounds from data ranges (docs/treatment.md, 'Formulation').

For a signal ``x`` (tracked joint angles, speeds, accelerations; tracked ID loads for
torque controls) the bounds are ``[min x - R, max x + R]`` with
``R = max(factor * (max x - min x), minimum_range)``: ``*_range_scale_factor`` and
``*_minimum_range`` of the settings (defaults: positions 2, speeds 1.5, accelerations 1,
torque controls 1; minimum ranges 0).
"""

from __future__ import annotations

import attrs
import numpy as np


@attrs.frozen
class RangeRule:
    """``factor`` (dimensionless) and ``minimum`` (signal units) of the range rule."""

    factor: float
    minimum: float = 0.0

    def __attrs_post_init__(self) -> None:
        if self.factor < 0 or self.minimum < 0:
            raise ValueError(f"range scale factor and minimum range must be >= 0, got {self.factor}, {self.minimum}")


def range_bounds(values: np.ndarray, rule: RangeRule) -> tuple[np.ndarray, np.ndarray]:
    """(lower (k,), upper (k,)) of the columns of ``values`` (n, k) by ``rule``."""
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        values = values[:, None]
    lo, hi = values.min(axis=0), values.max(axis=0)
    pad = np.maximum(rule.factor * (hi - lo), rule.minimum)
    return lo - pad, hi + pad


def check_guess_within(name: str, labels: tuple[str, ...], guess: np.ndarray, lower: np.ndarray,
                       upper: np.ndarray, tol: float = 1e-9) -> list[str]:
    """Descriptions of columns of ``guess`` (n, k) outside ``[lower, upper]`` (empty if none)."""
    problems = []
    guess = np.asarray(guess, dtype=float).reshape(-1, len(labels))
    for j, label in enumerate(labels):
        g = guess[:, j]
        span = max(upper[j] - lower[j], 1.0)
        below, above = g.min() < lower[j] - tol * span, g.max() > upper[j] + tol * span
        if below or above:
            problems.append(
                f"{name} '{label}': initial guess spans [{g.min():.6g}, {g.max():.6g}] outside the bounds "
                f"[{lower[j]:.6g}, {upper[j]:.6g}]"
            )
    return problems

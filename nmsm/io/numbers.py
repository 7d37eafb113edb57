"""Number formatting shared by the writers."""

from __future__ import annotations

import math


def full_precision(value: float) -> str:
    """Shortest text that reads back as exactly ``value`` (``NaN`` and ``inf`` as OpenSim writes them)."""
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return repr(float(value))


def significant15(value: float) -> str:
    """``value`` with 15 significant digits (the ``.osimx`` convention of the original)."""
    if math.isnan(value):
        return "NaN"
    if math.isinf(value):
        return "Inf" if value > 0 else "-Inf"
    return format(float(value), ".15g")

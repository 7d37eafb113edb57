"""``type=`` converters of the ``nmsm`` command-line options: a number out of its range is
argparse's usage error naming the option and the accepted range, e.g.

    nmsm id: error: argument --lowpass: -6 is out of range (expected a finite number > 0)

Each converter is a function of the option's text; see :func:`number`.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable


def _interval(low: float | None, high: float | None, low_open: bool, high_open: bool) -> str:
    """``> 0``, ``>= 0``, ``in [0, 1)``, ... for the messages."""
    if low is not None and high is not None:
        return f"in {'(' if low_open else '['}{low:g}, {high:g}{')' if high_open else ']'}"
    if low is not None:
        return f"{'>' if low_open else '>='} {low:g}"
    if high is not None:
        return f"{'<' if high_open else '<='} {high:g}"
    return ""


def number(
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
    integer: bool = False,
    name: str = "number",
) -> Callable[[str], float]:
    """A converter of option text to a finite float (or int) between ``low`` and ``high``
    (``*_open``: the bound itself excluded); anything else raises
    :class:`argparse.ArgumentTypeError` with the accepted range."""
    kind = "a whole number" if integer else "a finite number"
    interval = _interval(low, high, low_open, high_open)
    expected = f"{kind} {interval}".strip()

    def convert(text: str) -> float:
        try:
            value: float = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not {kind} (expected {expected})") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"'{text}' is not {kind} (expected {expected})")
        below = low is not None and (value <= low if low_open else value < low)
        above = high is not None and (value >= high if high_open else value > high)
        if below or above:
            raise argparse.ArgumentTypeError(f"{text} is out of range (expected {expected})")
        return value

    convert.__name__ = name
    return convert


#: any finite number (times)
finite_float = number(name="finite_float")
#: > 0 (cut-off frequencies, accuracies)
positive_float = number(0.0, low_open=True, name="positive_float")
#: >= 0 (paddings, thresholds, intervals where 0 means off)
non_negative_float = number(0.0, name="non_negative_float")
#: in [0, 1) (a share held out)
fraction = number(0.0, 1.0, high_open=True, name="fraction")
#: in (0, 100] (a percentage that can be reached)
percent = number(0.0, 100.0, low_open=True, name="percent")
#: 1, 2, ... (counts)
positive_int = number(1, integer=True, name="positive_int")

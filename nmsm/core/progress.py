"""Progress lines for long solves.

The command line switches them on (:func:`progress_every`, every 5 s by default; ``nmsm
--progress 0`` turns them off); library calls stay silent unless they do the same. A back end
asks :func:`solve_progress` for a reporter and calls :meth:`SolveProgress.tick` once per
iteration; a line is due only when ``interval`` seconds have passed since the last one (or
since the solve started), so short solves print nothing::

    [progress] mtp_task_1: iteration 40, cost 74.448, constraint violation 7.3e-03, 48 s
"""

from __future__ import annotations

import contextlib
import contextvars
import sys
import time
from collections.abc import Callable, Iterator
from typing import Any, TextIO

import attrs
import numpy as np

_INTERVAL: contextvars.ContextVar[float | None] = contextvars.ContextVar("nmsm_progress_interval", default=None)

#: seconds between progress lines of the command line
DEFAULT_INTERVAL = 5.0


@contextlib.contextmanager
def progress_every(seconds: float | None) -> Iterator[None]:
    """Within the block, solves report progress every ``seconds`` s (None or <= 0: off)."""
    token = _INTERVAL.set(seconds if seconds is not None and seconds > 0 else None)
    try:
        yield
    finally:
        _INTERVAL.reset(token)


@attrs.define
class SolveProgress:
    """Counts the iterations of one solve and prints a line at most every ``interval`` s."""

    name: str
    interval: float
    stream: TextIO = attrs.field(factory=lambda: sys.stderr)
    iteration: int = 0
    _start: float = attrs.field(factory=time.perf_counter)
    _last: float = attrs.field(init=False)

    def __attrs_post_init__(self) -> None:
        self._last = self._start

    def tick(self) -> bool:
        """Count one finished iteration; True when a line is due (then call :meth:`report`).
        Callers compute what the line shows only when it is due."""
        self.iteration += 1
        return time.perf_counter() - self._last >= self.interval

    def report(self, cost: float, violation: float | None = None) -> None:
        """Print the line of the current iteration: ``cost`` the objective, ``violation`` the
        largest constraint violation (None: the problem has no constraints)."""
        now = time.perf_counter()
        self._last = now
        parts = [f"iteration {self.iteration}", f"cost {cost:.6g}"]
        if violation is not None:
            parts.append(f"constraint violation {violation:.1e}")
        parts.append(f"{now - self._start:.0f} s")
        print(f"[progress] {self.name}: {', '.join(parts)}", file=self.stream, flush=True)


    def due(self) -> bool:
        """True when a line is due (``interval`` s since the last one), without counting an iteration."""
        return time.perf_counter() - self._last >= self.interval

    def report_items(self, done: int, total: int, unit: str) -> None:
        """Print ``[progress] <name>: <done> of <total> <unit>, <t> s`` (work counted in items)."""
        now = time.perf_counter()
        self._last = now
        print(f"[progress] {self.name}: {done} of {total} {unit}, {now - self._start:.0f} s", file=self.stream,
              flush=True)


def solve_progress(name: str) -> SolveProgress | None:
    """A reporter for a solve named ``name``, or None when progress lines are off."""
    interval = _INTERVAL.get()
    return None if interval is None else SolveProgress(name, interval)


def with_least_squares_progress(
    name: str, fun: Callable[[np.ndarray], np.ndarray], jac: Callable[[np.ndarray], Any]
) -> tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray], Any]]:
    """``fun`` and ``jac`` for scipy's ``least_squares``, reporting progress when it is on.

    scipy evaluates the Jacobian once per accepted step, at the point of the last residual
    evaluation: each Jacobian call counts one iteration, reported with that point's
    ``sum(r**2)``.
    """
    progress = solve_progress(name)
    if progress is None:
        return fun, jac
    last_residuals = [np.full(1, np.nan)]

    def reporting_fun(x: np.ndarray) -> np.ndarray:
        last_residuals[0] = r = fun(x)
        return r

    def reporting_jac(x: np.ndarray) -> Any:
        if progress.tick():
            r = last_residuals[0]
            progress.report(float(np.dot(r, r)))
        return jac(x)

    return reporting_fun, reporting_jac

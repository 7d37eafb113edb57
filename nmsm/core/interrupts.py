"""Ctrl-C during a CasADi solve stops the run instead of being taken for a solver result.

CasADi catches a ``KeyboardInterrupt`` raised inside IPOPT (its own signal check, or a
Python callback) and returns normally with the status ``NonIpopt_Exception_Thrown``; a tool
would then treat the interrupted iterate like any unconverged one and write it as results.
:func:`interrupt_after_solve` records the signal while the solve runs and raises
``KeyboardInterrupt`` once the solver has returned, so staged results are discarded
(:class:`nmsm.core.results.ResultsDirectory`) and ``nmsm`` exits with status 130. A back
end that kept the last iterate raises :class:`SolveInterrupted` with it, so a tool can
write it apart from results (treatment: ``<results>/last_iterate/``).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType
from typing import Any


class SolveInterrupted(KeyboardInterrupt):
    """A stop during a solve, carrying what the solver had reached: ``solution`` (the
    back end's :class:`~nmsm.core.problem.Solution` at the last iterate, not converged)."""

    def __init__(self, message: str, solution: Any = None) -> None:
        super().__init__(message)
        self.solution = solution


@contextlib.contextmanager
def interrupt_after_solve() -> Iterator[None]:
    """Run the block with SIGINT recorded; raise ``KeyboardInterrupt`` after it if one arrived.

    Only in the main thread and when SIGINT has Python's default handler (a handler the
    user installed is left alone); otherwise the block runs unchanged.
    """
    if threading.current_thread() is not threading.main_thread() or (
        signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        yield
        return
    arrived = False

    def record(signum: int, frame: FrameType | None) -> None:
        nonlocal arrived
        arrived = True
        raise KeyboardInterrupt

    signal.signal(signal.SIGINT, record)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    if arrived:
        raise KeyboardInterrupt("stopped by SIGINT during the solve")

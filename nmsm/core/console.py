"""What every tool prints on the command line: a start line, progress, an end summary.

The command line switches it on (:func:`console_output`); library calls (``nmsm.run``)
print nothing unless they do the same. The shape is the same for every tool::

    nmsm TO: settings to.xml; model leg.osim; trials gait_1; problem 25 mesh intervals, 1536 variables, 1206 constraints
    [progress] to: iteration 40, cost 0.0123, constraint violation 2.1e-05, 10 s      (nmsm.core.progress)
    nmsm TO summary:
      IPOPT Solve_Succeeded after 52 iterations, 14.2 s; objective 0.0121
      ...

The start line goes to standard output once the tool has read its inputs and knows the
size of its problem (:func:`announce`); the summary once it has written its results
(:func:`summarize`); progress lines go to standard error.
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import sys
from collections.abc import Iterable, Iterator, Sequence

_ON: contextvars.ContextVar[bool] = contextvars.ContextVar("nmsm_console_output", default=False)

#: trial names shown on a start line before "and N more"
SHOWN_TRIALS = 4


@contextlib.contextmanager
def console_output(enabled: bool = True) -> Iterator[None]:
    """Within the block, tools print their start line and end summary."""
    token = _ON.set(bool(enabled))
    try:
        yield
    finally:
        _ON.reset(token)


def console_enabled() -> bool:
    return _ON.get()


def _name(path: str | os.PathLike[str] | None) -> str:
    return "" if path is None else os.path.basename(os.fspath(path)) or os.fspath(path)


def _trials(trials: Sequence[str]) -> str:
    shown = ", ".join(trials[:SHOWN_TRIALS])
    return shown + (f" and {len(trials) - SHOWN_TRIALS} more" if len(trials) > SHOWN_TRIALS else "")


def start_line(tool: str, *, settings: str | os.PathLike[str] | None, model: str | os.PathLike[str] | None = None,
               trials: Sequence[str] = (), problem: str = "") -> str:
    """``nmsm <tool>: settings S; model M; trials a, b; problem P`` (file names without folders)."""
    parts = [f"settings {_name(settings)}"] if settings is not None else []
    if model is not None:
        parts.append(f"model {_name(model)}")
    if trials:
        parts.append(f"trials {_trials(list(trials))}")
    if problem:
        parts.append(f"problem {problem}")
    return f"nmsm {tool}: " + "; ".join(parts)


def announce(tool: str, *, settings: str | os.PathLike[str] | None, model: str | os.PathLike[str] | None = None,
             trials: Sequence[str] = (), problem: str = "") -> None:
    """Print the start line (:func:`start_line`) when console output is on."""
    if _ON.get():
        print(start_line(tool, settings=settings, model=model, trials=trials, problem=problem), flush=True)


def summary_text(tool: str, lines: Iterable[str]) -> str:
    """``nmsm <tool> summary:`` and the lines, indented."""
    return "\n".join([f"nmsm {tool} summary:", *(f"  {line}" for line in lines)])


def summarize(tool: str, lines: Iterable[str]) -> None:
    """Print the end summary (:func:`summary_text`) when console output is on."""
    if _ON.get():
        print(summary_text(tool, lines), file=sys.stdout, flush=True)

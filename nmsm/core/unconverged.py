"""One policy for a solve that did not reach its stopping criterion, in every tool.

A solve that stops at an iteration or evaluation limit, in an infeasible point or a failed
restoration (IPOPT), or after the evaluation limit (least squares) has not reached the
stopping criterion it was given. The tool (JMP, MTP with MTLI, NCP, GCP, TO/VO/DO) then
writes none of its usual results: it writes what it would have written from the last
iterate, and ``diagnosis.txt``, into ``<results>/last_iterate/`` (:func:`write_last_iterate`,
through the results folder's staging, so an earlier run's results are moved into
``superseded/`` and nothing of this run looks like a result) and raises
:class:`~nmsm.errors.SolverError` naming the folder: ``nmsm`` exits with status 1, and a
pipeline stops at that stage.

With ``accept_unconverged=True`` (``nmsm run --accept-unconverged``, ``nmsm pipeline
--accept-unconverged``) the results are written where they normally go, with a warning,
and every file of the results is stamped (:mod:`nmsm.core.unconverged_stamp`): a header
line ``unconverged=...`` in ``.sto``/``.mot`` tables, an XML comment ``UNCONVERGED: ...`` after
the declaration of ``.osim``/``.osimx``/``.xml`` files, a first line ``UNCONVERGED: ...`` in
``.txt``/``.log`` files and an ``"unconverged"`` entry in JSON objects. Other files (figures)
are left as they are.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from pathlib import Path

from nmsm.core.results import ResultsDirectory
from nmsm.core.unconverged_stamp import stamp_unconverged
from nmsm.errors import SolverError

#: folder (inside the results folder) of an unconverged run's last iterate and diagnosis
LAST_ITERATE = "last_iterate"
#: the diagnosis written beside the last iterate
DIAGNOSIS_FILE = "diagnosis.txt"
#: the command-line option accepting unconverged results
ACCEPT_OPTION = "--accept-unconverged"


def unconverged_note(what: Sequence[str]) -> str:
    """One line naming the solves that did not converge (``what``: e.g. ``"MTP task 2:
    IPOPT Maximum_Iterations_Exceeded after 1 iterations"``)."""
    return "did not reach its stopping criterion: " + "; ".join(what)


def status_hints(status: str, limit: str) -> list[str]:
    """What to try for a solver ``status`` (``limit``: the settings element of the iteration
    or evaluation limit, e.g. ``<max_iterations>``)."""
    hints = []
    if "maximum" in status.lower():  # IPOPT's Maximum_Iterations_Exceeded, an evaluation limit
        hints.append(f"The solver reached {limit}: raise it, or start from a better initial guess.")
    if "Infeasible" in status:
        hints.append("IPOPT found the constraints locally infeasible: check the constraint bounds listed as VIOLATED "
                     "below (min_error/max_error), the variable bounds (range scale factors) and the initial guess.")
    if "Restoration" in status:
        hints.append("IPOPT's restoration phase failed: the problem may be infeasible or badly scaled near the guess.")
    if "Invalid_Number" in status or "not finite" in status:
        hints.append("A cost or constraint was not finite at an iterate: check the model and data for values outside "
                     "their range.")
    return hints


def diagnosis_text(note: str, hints: Sequence[str], details: str) -> str:
    """``diagnosis.txt``: what did not converge, what to try, then the tool's details."""
    body = "\n".join(hints) + "\n\n" if hints else ""
    return f"Diagnosis\n=========\nThe solve {note}.\n\n{body}{details.rstrip()}\n"


def write_last_iterate(results: ResultsDirectory, write: Callable[[Path], None], diagnosis: str, note: str) -> Path:
    """Write the last iterate (``write(folder)`` writes the usual files into ``folder``),
    stamped, and ``diagnosis.txt`` into ``<results>/last_iterate/`` through the results
    folder's staging; returns that folder."""
    with results.task(LAST_ITERATE) as stage:
        folder = stage / LAST_ITERATE
        folder.mkdir(parents=True, exist_ok=True)
        write(folder)
        stamp_unconverged(folder, note)
        (folder / DIAGNOSIS_FILE).write_text(diagnosis, encoding="utf-8")
    return results.path / LAST_ITERATE


def unconverged_error(source: object, note: str, saved: Path | None, hint: str = "") -> SolverError:
    """The :class:`SolverError` of an unconverged run of ``source`` (the settings file)."""
    accept = f"; {ACCEPT_OPTION} writes the results anyway, stamped as unconverged"
    return SolverError(f"{source}: the solve {note}{hint}{accept}",
                       last_iterate_path=str(saved) if saved is not None else None)


def warn_accepted(source: object, note: str) -> None:
    """The warning of results written although the solve did not converge."""
    warnings.warn(f"{source}: the solve {note}; results written because unconverged results were accepted, "
                  "each file stamped 'UNCONVERGED'", stacklevel=3)


def settle(results: ResultsDirectory | None, source: object, failures: Sequence[str], *, accept: bool,
           write: Callable[[Path], None], diagnosis: Callable[[str], str], hint: str = "") -> str | None:
    """Apply the policy after a tool's solves: ``failures`` names each solve that did not
    converge (empty: all did). Unconverged and not ``accept``: the last iterate is written
    (``write``, ``diagnosis(note)``) and :class:`SolverError` raised. Returns the stamp note
    for the results (None when every solve converged)."""
    if not failures:
        return None
    note = unconverged_note(failures)
    if accept:
        warn_accepted(source, note)
        return note
    saved = write_last_iterate(results, write, diagnosis(note), note) if results is not None else None
    raise unconverged_error(source, note, saved, hint)

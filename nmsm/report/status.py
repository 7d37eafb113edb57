"""The report's status row of a stage: converged or not, the headline errors, the time.

Everything is read from the files a tool writes into its results folder (its summary
text, JSON or tables), so a results folder from any run (a pipeline's stage, a tool run
alone, an earlier nmsm) reports the same way. One reader per kind of results folder
(:data:`STATUS_READERS`); a kind without a reader gets an empty row.

Convergence comes from the solver statuses the summaries record: IPOPT's
``Solve_Succeeded`` / ``Solved_To_Acceptable_Level``, scipy's ``... termination
condition(s) ... satisfied``, JMP's ``converged`` flag. Any other status (e.g.
``Maximum_Iterations_Exceeded``) is not converged; a folder whose summary names no status
is unknown (``None``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterable
from pathlib import Path

import attrs
import numpy as np

#: solver statuses that mean a converged solve
CONVERGED_STATUSES = frozenset({"Solve_Succeeded", "Solved_To_Acceptable_Level", "nothing to optimize"})

#: ``Solution.summary()``'s first line: ``<backend>[ (<detail>)]: <status> after <n> iterations, <t> s, cost ...``
_SUMMARY = re.compile(r"\b(?:ipopt|least_squares)(?: \([^)]*\))?: (.+?) after (\d+) iterations, ([\d.]+) s")
#: a treatment convergence file's first line: ``<problem>: IPOPT <status> after <n> iterations, <t> s``
_TREATMENT = re.compile(r"IPOPT (\S+) after (\d+) iterations, ([\d.]+) s")
#: MTP's ``mtpSummary.txt``: ``task <k>: <status>; cost <c>; <n> iterations; <t> s``
_MTP = re.compile(r"^task \d+: (.+?); cost \S+; (\d+) iterations; ([\d.]+) s", re.MULTILINE)


@attrs.frozen
class SolverOutcome:
    """One solve recorded in a summary: status text, iterations, wall time (s)."""

    status: str
    iterations: int
    seconds: float

    @property
    def converged(self) -> bool:
        return is_converged(self.status)


@attrs.frozen
class StageStatus:
    """A stage's status row: ``converged`` (None: no solve or not recorded), the solver
    statuses, the headline errors (text) and the solve time (s, None when unknown)."""

    converged: bool | None = None
    solver: str = ""
    headline: str = ""
    seconds: float | None = None


def is_converged(status: str) -> bool:
    """True for a solver status that means converged (module docstring)."""
    status = status.strip()
    return status in CONVERGED_STATUSES or ("termination condition" in status and "satisfied" in status)


def solver_outcomes(text: str) -> list[SolverOutcome]:
    """Every solve a summary text records (``Solution.summary()`` lines, a treatment
    convergence file's first line, MTP's task lines), in order."""
    found = []
    for pattern in (_SUMMARY, _TREATMENT, _MTP):
        for match in pattern.finditer(text):
            found.append((match.start(), SolverOutcome(match.group(1).strip(), int(match.group(2)),
                                                       float(match.group(3)))))
    return [outcome for _, outcome in sorted(found, key=lambda item: item[0])]


def _from_outcomes(outcomes: Iterable[SolverOutcome], headline: str) -> StageStatus:
    outcomes = list(outcomes)
    if not outcomes:
        return StageStatus(None, "", headline, None)
    statuses = list(dict.fromkeys(o.status for o in outcomes))
    return StageStatus(all(o.converged for o in outcomes), ", ".join(statuses), headline,
                       sum(o.seconds for o in outcomes))


def _read(path: Path) -> str:
    return path.read_text(encoding="utf-8") if path.is_file() else ""


def _number(pattern: str, text: str) -> float | None:
    match = re.search(pattern, text)
    return float(match.group(1)) if match else None


def jmp_status(folder: Path) -> StageStatus:
    path = folder / "jmp_results.json"
    if not path.is_file():
        return StageStatus()
    data = json.loads(path.read_text(encoding="utf-8"))
    solvers = [task.get("solver", {}) for task in data.get("tasks", [])]
    parts = []
    for task in data.get("tasks", []):
        overall = next((e for e in task.get("errors", []) if e.get("group") == "all markers"), None)
        if overall is not None:
            parts.append(f"{task['label']}: marker RMS {1000 * overall['rms_before']:.2f} → "
                         f"{1000 * overall['rms_after']:.2f} mm")
    return StageStatus(all(bool(s.get("converged")) for s in solvers) if solvers else None,
                       ", ".join(dict.fromkeys(str(s.get("status", "")) for s in solvers)), "; ".join(parts),
                       data.get("wall_time"))


def mtp_status(folder: Path) -> StageStatus:
    from nmsm.report.tables import mtp_moment_errors

    errors = mtp_moment_errors(folder)
    headline = ""
    if errors:
        worst = max(errors, key=lambda e: e[2])
        headline = (f"joint moment RMS {np.mean([e[2] for e in errors]):.3g} N·m mean, "
                    f"{worst[2]:.3g} N·m at most ({worst[1]}, {worst[0]})")
    return _from_outcomes(solver_outcomes(_read(folder / "mtpSummary.txt")), headline)


def ncp_status(folder: Path) -> StageStatus:
    text = _read(folder / "commandWindowOutput.txt")
    parts = []
    moment = _number(r"mean over coordinates\s+([-\d.eE+]+)", text)
    if moment is not None:
        parts.append(f"moment RMS {moment:.3g} N·m")
    activation = _number(r"activation RMS vs MTP \(pooled\): ([-\d.eE+]+)", text)
    if activation is not None:
        parts.append(f"activation RMS {activation:.3g}")
    vaf = _number(r"VAF ([-\d.eE+]+) %", text)
    if vaf is not None:
        parts.append(f"VAF {vaf:.1f} %")
    return _from_outcomes(solver_outcomes(text), ", ".join(parts))


def gcp_status(folder: Path) -> StageStatus:
    from nmsm.report.tables import gcp_errors

    parts = []
    for foot, values in gcp_errors(folder).items():
        forces = [values[k] for k in ("Fx (N)", "Fy (N)", "Fz (N)") if k in values]
        moments = [values[k] for k in ("Mx (N m)", "My (N m)", "Mz (N m)") if k in values]
        if forces and moments:
            parts.append(f"{foot}: force RMS ≤ {max(forces):.3g} N, moment RMS ≤ {max(moments):.3g} N·m")
    return _from_outcomes(solver_outcomes(_read(folder / "commandWindowOutput.txt")), "; ".join(parts))


def treatment_status(folder: Path) -> StageStatus:
    from nmsm.report.tables import treatment_tracking_errors

    files = sorted(folder.glob("*_convergence.txt")) or sorted(folder.glob("*/*_convergence.txt"))
    outcomes, parts = [], []
    for path in files:
        text = path.read_text(encoding="utf-8")
        outcomes += solver_outcomes(text.split("\n", 1)[0])
        violated = re.search(r"^(\d+) constraint block\(s\) violated", text, re.MULTILINE)
        if violated:
            parts.append(f"{violated.group(1)} constraint block(s) violated")
    tracking = treatment_tracking_errors(folder)
    worst = []
    for rotational, scale, unit in ((True, 1.0, "deg"), (False, 1000.0, "mm")):
        rows = [e for e in tracking if e[3] is rotational]
        if rows:
            row = max(rows, key=lambda e: e[1])
            worst.append(f"≤ {scale * row[1]:.3g} {unit} ({row[0]})")
    if worst:
        parts.insert(0, "tracking RMS " + ", ".join(worst))
    return _from_outcomes(outcomes, "; ".join(parts))


#: results kind -> status reader
STATUS_READERS: dict[str, Callable[[Path], StageStatus]] = {
    "jmp": jmp_status,
    "mtp": mtp_status,
    "ncp": ncp_status,
    "gcp": gcp_status,
    "treatment": treatment_status,
}


def stage_status(kind: str, folder: Path) -> StageStatus:
    """The status row of a results folder of ``kind`` (an empty row for kinds without a reader
    or a folder whose files cannot be read)."""
    reader = STATUS_READERS.get(kind)
    if reader is None or not folder.is_dir():
        return StageStatus()
    try:
        return reader(folder)
    except (OSError, ValueError, KeyError) as exc:
        return StageStatus(None, "", f"status unavailable ({type(exc).__name__}: {exc})", None)

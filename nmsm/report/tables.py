"""The tables of the report, one builder per kind of results folder.

Each builder reads only files of a results folder and returns :class:`ReportTable` objects
(title, column headers, rows of text). Layouts follow the NMSM Pipeline paper's tables where
they apply: marker distance errors before and after JMP (per joint and overall); the MTP
muscle parameters (electromechanical delay, activation time constant, nonlinearity, EMG
scale, optimal fiber and tendon slack lengths) and the joint-moment fit; NCP's fit (moments,
activations, VAF); GCP's contact properties and ground-reaction errors; treatment tracking
errors per coordinate and the solver's outcome.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np


@attrs.frozen
class ReportTable:
    """A table: ``headers`` (k,) and ``rows`` (n, k) of text; ``note`` under it."""

    title: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    note: str = ""


def _f(value: float | None, digits: int = 4) -> str:
    return "" if value is None or not np.isfinite(value) else f"{value:.{digits}g}"


def jmp_tables(folder: Path) -> list[ReportTable]:
    data = json.loads((folder / "jmp_results.json").read_text(encoding="utf-8"))
    out = []
    for task in data["tasks"]:
        rows = tuple((e["group"], str(len(e["markers"])), _f(1000 * e["rms_before"]), _f(1000 * e["rms_after"]),
                      _f(1000 * e["max_before"]), _f(1000 * e["max_after"])) for e in task["errors"]
                     if not e["group"].startswith("marker "))
        out.append(ReportTable(f"JMP task '{task['label']}': marker distance errors (mm)",
                               ("markers", "n", "RMS before", "RMS after", "max before", "max after"), rows))
        params = tuple((p["label"], _f(p["initial"]), _f(p["final"]), _f(p["final"] - p["initial"]))
                       for p in task.get("parameters", []))
        if params:
            out.append(ReportTable(f"JMP task '{task['label']}': parameters (m, rad)",
                                   ("parameter", "initial", "final", "change"), params))
    return out


def mtp_tables(folder: Path) -> list[ReportTable]:
    from nmsm.io.osimx import read_osimx
    from nmsm.io.storage import read_storage, strip_load_suffix

    out = []
    osimx_files = sorted(folder.glob("*.osimx"))
    if osimx_files:
        muscles = read_osimx(osimx_files[0]).muscles
        rows = tuple((name, _f(None if m.electromechanical_delay is None else 100 * m.electromechanical_delay, 3),
                      _f(None if m.activation_time_constant is None else 10 * m.activation_time_constant, 3),
                      _f(m.activation_nonlinearity_constant, 3), _f(m.emg_scale_factor, 3),
                      _f(None if m.optimal_fiber_length is None else 100 * m.optimal_fiber_length, 4),
                      _f(None if m.tendon_slack_length is None else 100 * m.tendon_slack_length, 4))
                     for name, m in muscles.items())
        out.append(ReportTable("MTP muscle parameters",
                               ("muscle", "EMD (ms)", "act. time constant (ms)", "nonlinearity", "EMG scale",
                                "optimal fiber length (cm)", "tendon slack length (cm)"), rows))
    model_files = sorted((folder / "modelMoments").glob("*_modelMoments.sto"))
    measured_files = sorted((folder / "Analysis" / "inverseDynamicsJointMoments").glob("*.sto"))
    rows = []
    for model_file, measured_file in zip(model_files, measured_files):
        model, measured = read_storage(model_file), read_storage(measured_file)
        for label in measured.labels:
            name = strip_load_suffix(label)
            column = next((c for c in model.labels if strip_load_suffix(c) == name), None)
            if column is None:
                continue
            error = model.column(column) - measured.column(label)
            rows.append((model_file.stem.replace("_modelMoments", ""), name, _f(np.sqrt(np.mean(error**2)), 3),
                         _f(np.abs(error).max(), 3), _f(np.sqrt(np.mean(measured.column(label) ** 2)), 3)))
    if rows:
        out.append(ReportTable("MTP joint moments: model vs inverse dynamics (N m)",
                               ("trial", "coordinate", "RMS error", "max error", "RMS of ID"), tuple(rows)))
    return out


def ncp_tables(folder: Path) -> list[ReportTable]:
    log = folder / "commandWindowOutput.txt"
    lines = log.read_text(encoding="utf-8").splitlines()[:12] if log.is_file() else []
    rows = tuple(("", line.strip()) for line in lines)
    out = [ReportTable("NCP run", ("", "summary"), rows)] if rows else []
    info = folder / "ncpRunInfo.json"
    if info.is_file():
        data = json.loads(info.read_text(encoding="utf-8"))
        groups = tuple((g["name"], str(g["synergies"]), str(len(g["muscles"]))) for g in data.get("groups", []))
        out.append(ReportTable("NCP synergy groups", ("group", "synergies", "muscles"), groups))
    return out


def gcp_tables(folder: Path) -> list[ReportTable]:
    from nmsm.io.osimx import read_osimx

    out = []
    for osimx_file in sorted(folder.glob("*.osimx"))[:1]:
        surfaces = read_osimx(osimx_file).contact_surfaces
        rows = []
        for k, s in enumerate(surfaces, start=1):
            constants = np.array([spring.spring_constant for spring in s.springs])
            rows.append((str(k), s.hindfoot_body, str(constants.size),
                         f"{_f(constants.mean())} ({_f(constants.min())}-{_f(constants.max())})",
                         _f(1000 * s.resting_spring_length), _f(s.damping_factor), _f(s.dynamic_friction_coefficient),
                         _f(s.viscous_friction_coefficient)))
        out.append(ReportTable("GCP contact properties",
                               ("surface", "hindfoot", "springs", "spring constant N/m mean (range)",
                                "resting length (mm)", "damping (s/m)", "dynamic friction", "viscous friction (s/m)"),
                               tuple(rows)))
    for errors in sorted(folder.glob("*_gcpErrors.txt")):
        lines = [line.split() for line in errors.read_text(encoding="utf-8").splitlines()[2:] if line.strip()]
        rows = tuple((" ".join(p[:-1]), p[-1]) for p in lines if len(p) >= 2)
        out.append(ReportTable("GCP RMS errors (modeled vs experimental)", ("quantity", "foot 1"), rows))
    return out


def treatment_tables(folder: Path) -> list[ReportTable]:
    from nmsm.io.storage import read_storage

    out = []
    for convergence in sorted(folder.glob("*_convergence.txt")):
        lines = convergence.read_text(encoding="utf-8").splitlines()[:14]
        out.append(ReportTable(f"{convergence.stem}", ("",), tuple((line,) for line in lines)))
    modeled = sorted((folder / "Analysis").glob("*_modeledPositions.sto"))
    tracked = sorted((folder / "Analysis").glob("*_trackedPositions.sto"))
    for m_file, t_file in zip(modeled, tracked):
        m, t = read_storage(m_file), read_storage(t_file)
        rows = []
        for label in m.labels:
            if not t.has(label):
                continue
            error = m.column(label) - t.column(label)
            error = error if m.in_degrees else np.degrees(error)
            rows.append((label, _f(np.sqrt(np.mean(error**2)), 3), _f(np.abs(error).max(), 3)))
        if rows:
            out.append(ReportTable("Tracking: modeled vs tracked coordinates (deg for rotations)",
                                   ("coordinate", "RMS", "max"), tuple(rows)))
    return out


def analysis_tables(folder: Path) -> list[ReportTable]:
    report = folder / "analysis_report.txt"
    if not report.is_file():
        return []
    lines = report.read_text(encoding="utf-8").splitlines()
    return [ReportTable("IK, ID and muscle analysis", ("",), tuple((line,) for line in lines))]


def checks_table(checks: Sequence) -> ReportTable:
    """The known-answer comparison of the example (:class:`nmsm.examples.subject_recovery.Check`)."""
    rows = []
    for c in checks:
        error = f"{100 * c.error:+.1f} %" if c.unit == "relative" else f"{c.error:+.4g} {c.unit}"
        verdict = {True: "within", False: "OUT", None: "reported"}[c.ok]
        tolerance = "" if c.tolerance is None else (f"{100 * c.tolerance:g} %" if c.unit == "relative"
                                                      else f"{c.tolerance:.3g} {c.unit}")
        rows.append((c.stage, c.quantity, _f(c.truth), _f(c.recovered), error, tolerance, verdict, c.note))
    return ReportTable("Recovered vs known truth", ("stage", "quantity", "truth", "recovered", "error", "tolerance",
                                                     "verdict", "note"), tuple(rows))


#: results kind -> table builder
BUILDERS = {
    "jmp": jmp_tables,
    "analysis": analysis_tables,
    "mtp": mtp_tables,
    "ncp": ncp_tables,
    "gcp": gcp_tables,
    "treatment": treatment_tables,
}

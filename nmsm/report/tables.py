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


@attrs.frozen
class ReportText:
    """Free text of a results folder (a tool's summary), shown preformatted."""

    title: str
    text: str


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


def mtp_tables(folder: Path) -> list[ReportTable | ReportText]:
    from nmsm.io.osimx import read_osimx

    out: list[ReportTable | ReportText] = []
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
    rows = tuple((trial, name, _f(rms, 3), _f(peak, 3), _f(reference, 3))
                 for trial, name, rms, peak, reference in mtp_moment_errors(folder))
    if rows:
        out.append(ReportTable("MTP joint moments: model vs inverse dynamics (N m)",
                               ("trial", "coordinate", "RMS error", "max error", "RMS of ID"), rows))
    summary = folder / "mtpSummary.txt"
    if summary.is_file():
        out.append(ReportText("MTP solver summary", summary.read_text(encoding="utf-8")))
    return out


def mtp_moment_errors(folder: Path) -> list[tuple[str, str, float, float, float]]:
    """``(trial, coordinate, RMS error, max |error|, RMS of ID)`` (N·m) of MTP's modeled joint
    moments against inverse dynamics, per trial and coordinate."""
    from nmsm.io.storage import read_storage, strip_load_suffix

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
            rows.append((model_file.stem.replace("_modelMoments", ""), name, float(np.sqrt(np.mean(error**2))),
                         float(np.abs(error).max()), float(np.sqrt(np.mean(measured.column(label) ** 2)))))
    return rows


def ncp_tables(folder: Path) -> list[ReportTable | ReportText]:
    log = folder / "commandWindowOutput.txt"
    out: list[ReportTable | ReportText] = []
    if log.is_file():
        out.append(ReportText("NCP run", log.read_text(encoding="utf-8")))
    info = folder / "ncpRunInfo.json"
    if info.is_file():
        data = json.loads(info.read_text(encoding="utf-8"))
        groups = tuple((g["name"], str(g["synergies"]), str(len(g["muscles"]))) for g in data.get("groups", []))
        out.append(ReportTable("NCP synergy groups", ("group", "synergies", "muscles"), groups))
    return out


def gcp_tables(folder: Path) -> list[ReportTable | ReportText]:
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
    errors = gcp_errors(folder)
    if errors:
        feet = list(errors)
        labels = list(dict.fromkeys(label for values in errors.values() for label in values))
        out.append(ReportTable("GCP RMS errors (modeled vs experimental)", ("quantity", *feet),
                               tuple((label, *(_f(errors[f].get(label)) for f in feet)) for label in labels)))
    log = folder / "commandWindowOutput.txt"
    if log.is_file():
        out.append(ReportText("GCP run", log.read_text(encoding="utf-8")))
    return out


def gcp_errors(folder: Path) -> dict[str, dict[str, float]]:
    """GCP's RMS errors (``<model>_gcpErrors.txt``, :func:`nmsm.tools.gcp.report.format_error_table`:
    a title, a header of 14-character column names after a 22-character label column, one
    row per quantity): column (foot) -> quantity label -> value (N, N m, mm, deg as the
    labels say). With several files the columns are prefixed by the file's model name."""
    files = sorted(folder.glob("*_gcpErrors.txt"))
    out: dict[str, dict[str, float]] = {}
    for path in files:
        lines = [line for line in path.read_text(encoding="utf-8").splitlines() if line.strip()]
        if len(lines) < 3:
            continue
        names = [lines[1][22 + 14 * k:22 + 14 * (k + 1)].strip() for k in range((len(lines[1]) - 22 + 13) // 14)]
        names = [n for n in names if n and n != "ratio"]
        prefix = f"{path.stem.removesuffix('_gcpErrors')}: " if len(files) > 1 else ""
        for line in lines[2:]:
            label, values = line[:22].strip(), line[22:].split()
            for name, value in zip(names, values):
                out.setdefault(prefix + name, {})[label] = float(value)
    return out


def treatment_tables(folder: Path) -> list[ReportTable | ReportText]:
    out: list[ReportTable | ReportText] = []
    rows = tuple((label, _f(rms, 3), _f(peak, 3)) for label, rms, peak, _ in treatment_tracking_errors(folder))
    if rows:
        out.append(ReportTable("Tracking: modeled vs tracked coordinates (deg for rotations, m for translations)",
                               ("coordinate", "RMS", "max"), rows))
    for convergence in sorted(folder.glob("*_convergence.txt")) or sorted(folder.glob("*/*_convergence.txt")):
        out.append(ReportText(str(convergence.relative_to(folder)), convergence.read_text(encoding="utf-8")))
    return out


def treatment_tracking_errors(folder: Path) -> list[tuple[str, float, float, bool]]:
    """``(coordinate, RMS, max |error|, rotational)`` of the modeled vs tracked state
    coordinates (``Analysis/*_modeledPositions.sto``); degrees for rotations (labels the
    model-free files cannot tell apart: a coordinate ending in ``_tx``, ``_ty``, ``_tz`` is
    translational, m)."""
    from nmsm.io.storage import read_storage

    rows = []
    modeled = sorted((folder / "Analysis").glob("*_modeledPositions.sto"))
    tracked = sorted((folder / "Analysis").glob("*_trackedPositions.sto"))
    for m_file, t_file in zip(modeled, tracked):
        m, t = read_storage(m_file), read_storage(t_file)
        for label in m.labels:
            if not t.has(label):
                continue
            rotational = not label.endswith(("_tx", "_ty", "_tz"))
            error = m.column(label) - t.column(label)
            if rotational and not m.in_degrees:
                error = np.degrees(error)
            rows.append((label, float(np.sqrt(np.mean(error**2))), float(np.abs(error).max()), rotational))
    return rows


def analysis_tables(folder: Path) -> list[ReportTable | ReportText]:
    report = folder / "analysis_report.txt"
    if not report.is_file():
        return []
    return [ReportText("IK, ID and muscle analysis", report.read_text(encoding="utf-8"))]


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

"""Correctness checks of the full-body gait case's TO -> VO -> DO chain (issue 24, item 4).

* :func:`tracking_errors`: per tracking term of a run, the RMS of its raw quantity over the
  collocation points and the term's ``max_allowable_error`` (same units);
* :func:`vo_versus_to`: largest differences between a VO solution and the TO results it
  started from - rotations (deg), pelvis translations (m), loads of the non-root state
  coordinates (N·m; the last node, where controls are extrapolated, left out);
* :func:`design_change`: a DO's static parameters and, per cost term, its cost at the DO's
  solution minus its cost at the VO's solution in the DO's problem (negative: the term
  the design improved), largest changes first;
* :func:`run_chain`: TO, VO and DO of a case's settings files with all three checks, as
  a JSON-ready dict (the slow test and ``benchmarks/bench_fullbody.py`` use it).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from nmsm.examples import fullbody_data as fd

TRANSLATIONS = ("pelvis_tx", "pelvis_ty", "pelvis_tz")


def tracking_errors(run: Any) -> dict[str, tuple[float, float]]:
    """``label -> (RMS, max_allowable_error)`` of every continuous tracking term."""
    from nmsm.tools.treatment.summary import tracking_rms

    rms = tracking_rms(run)
    limits = {t.label: float(t.max_allowable_error) for t in run.prepared.terms if t.label in rms}
    return {label: (value, limits[label]) for label, value in rms.items()}


def vo_versus_to(run: Any, to_folder: Path) -> dict[str, float]:
    """Max |Δq| (deg; m for the pelvis translations) and |Δτ| (N·m) of a VO against its TO."""
    from nmsm.io.storage import read_storage

    trial = run.prepared.settings.trial_name
    model = run.prepared.model
    states = list(run.prepared.data.state_coordinates)
    t = run.result.time
    ik = read_storage(to_folder / "IKData" / f"{trial}.sto")
    iddata = read_storage(to_folder / "IDData" / f"{trial}.sto")

    def at_nodes(table: Any, labels: list[str]) -> np.ndarray:
        time = table.time - table.time[0]
        return np.column_stack([np.interp(t, time, table.column(label)) for label in labels])

    rotations = [c for c in states if c not in TRANSLATIONS]
    columns = {c: model.coordinate_names.index(c) for c in states}
    dq = run.result.positions[:, [columns[c] for c in rotations]] - at_nodes(ik, rotations)
    dx = run.result.positions[:, [columns[c] for c in TRANSLATIONS]] - at_nodes(ik, list(TRANSLATIONS))
    driven = [c for c in states if c not in fd.PELVIS]
    loads = [model.load_label(c) for c in driven]
    dtau = run.result.inverse_dynamics[:-1, [columns[c] for c in driven]] - at_nodes(iddata, loads)[:-1]
    return {"max_angle_deg": float(np.degrees(np.max(np.abs(dq)))), "max_translation_m": float(np.max(np.abs(dx))),
            "max_moment_Nm": float(np.max(np.abs(dtau)))}


def design_change(do_run: Any, do_settings: Path, vo_folder: Path) -> dict[str, Any]:
    """The DO's parameters and its cost terms' change from the VO's solution (module docstring)."""
    from nmsm.tools.treatment.compare import score_solution
    from nmsm.tools.treatment.design import PARAMETER_PREFIX

    at_vo = score_solution(do_settings, vo_folder, write_results=False).solution.term_costs
    at_do = do_run.solution.term_costs
    change = sorted(((name, at_do[name] - at_vo.get(name, 0.0)) for name in at_do), key=lambda kv: -abs(kv[1]))
    parameters = {name: np.asarray(value, float).ravel().tolist() for name, value in do_run.solution.values.items()
                  if name.startswith(PARAMETER_PREFIX)}
    return {"parameters": parameters, "term_changes": change[:8]}


def _run(path: Path, **options: Any) -> Any:
    from nmsm.tools.treatment.run import run_settings

    return run_settings(path, **options)


def run_chain(settings: dict[str, str | os.PathLike[str]], **options: Any) -> dict[str, Any]:
    """TO, VO, DO of ``settings`` (tool -> file) with the checks; stops at the first failure."""
    out: dict[str, Any] = {}
    folders: dict[str, Path] = {}
    for tool in ("to", "vo", "do"):
        path = Path(settings[tool])
        run = _run(path, **options)
        s = run.solution
        row: dict[str, Any] = {"success": bool(s.success), "status": s.status, "iterations": int(s.iterations),
                               "solve_s": float(s.wall_time), "build_s": float(run.build_time)}
        folders[tool] = Path(run.results_directory)
        row["files"] = sorted(str(p.relative_to(folders[tool])) for p in folders[tool].rglob("*") if p.is_file())
        if tool == "to":
            row["tracking"] = tracking_errors(run)
        elif tool == "vo":
            row["versus_to"] = vo_versus_to(run, folders["to"])
        else:
            row["design"] = design_change(run, path, folders["vo"])
        out[tool] = row
        if not s.success:
            break
    return out

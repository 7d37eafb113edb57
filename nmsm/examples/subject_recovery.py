"""What each stage of the example recovered, against the synthetic subject's truth.

Each function reads a stage's results folder and returns :class:`Check` rows: a quantity,
its true and recovered values, the error, the tolerance the example holds it to and
whether it is within. Tolerances (the example's acceptance limits, set from what the data
can determine; see docs/pipeline.md):

==========  ==================================================================================
JMP         every joint-frame angle within 0.25 deg of the true model's
MTP         joint moments fitted within 3 N m RMS per coordinate; optimal fiber and tendon
            slack lengths within 2 % for every muscle (MTLI fits them to the passive trials,
            which stretch every muscle; :data:`LENGTH_TOLERANCE`); electromechanical delay
            within 15 ms and activation time constant within 5 ms for every muscle whose
            activation in the trial exceeds 0.15 (:data:`ACTIVE`); the others are reported,
            not judged (a muscle that hardly acts cannot be characterized by its moments)
NCP         the synergies' activations ``c W`` within 0.02 RMS of the activations NCP was given
            (MTP's) and within 0.03 RMS of the true activations. The synergy vectors
            themselves are reported, not judged: a non-negative factorization of one trial's
            activations is not unique (an exact factorization of the *true* activations finds
            vectors with cosine similarity 0.1-0.99 to the true ones,
            :func:`exact_nmf_similarity`); their span is reported too
GCP         resting spring length within 15 %, dynamic friction within 10 %, ground reactions
            reproduced within 5 N and 1 N m RMS; spring constants within 30 % RMS
            (damping and viscous friction are reported only: the stance hardly excites them)
treatment   TO tracks the experimental joint angles within 3 deg RMS; VO's and DO's changes
            of the joint angles are reported (DO: the predicted effect of weaker plantarflexors)
==========  ==================================================================================
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

#: a muscle is "active" in the trial (its activation parameters judged) above this peak activation
ACTIVE = 0.15
#: relative tolerance of the optimal fiber and tendon slack lengths (every muscle)
LENGTH_TOLERANCE = 0.02


@attrs.frozen
class Check:
    """One recovered quantity. ``ok`` is None when the quantity is reported, not judged."""

    stage: str
    quantity: str
    truth: float
    recovered: float
    error: float
    tolerance: float | None
    unit: str
    ok: bool | None
    note: str = ""


def _check(stage: str, quantity: str, truth: float, recovered: float, tolerance: float | None, unit: str, *,
           relative: bool = False, note: str = "") -> Check:
    error = (recovered - truth) / truth if relative else recovered - truth
    ok = None if tolerance is None else bool(abs(error) <= tolerance)
    return Check(stage, quantity, float(truth), float(recovered), float(error), tolerance, unit, ok, note)


# ------------------------------------------------------------------------------------ JMP
def jmp_checks(truth: dict[str, Any], results: Path) -> list[Check]:
    data = json.loads((results / "jmp_results.json").read_text(encoding="utf-8"))
    recovered: dict[str, float] = {}
    for task in data["tasks"]:
        for row in task.get("parameters", []):
            recovered[row["label"]] = float(row["final"])
    tolerance = np.radians(0.25)
    return [_check("JMP", label, value, recovered[label], tolerance, "rad")
            for label, value in truth["joints"].items() if label in recovered]


# ------------------------------------------------------------------------------------ MTP
def _trial_activation_peaks(truth_dir: Path, truth: dict[str, Any]) -> dict[str, float]:
    sim = np.load(truth_dir / "simulation.npz")
    window = (sim["time"] >= truth["trial_window"][0]) & (sim["time"] <= truth["trial_window"][1])
    return {m: float(sim["a"][window, k].max()) for k, m in enumerate(truth["muscle_order"])}


def mtp_checks(truth: dict[str, Any], truth_dir: Path, results: Path) -> list[Check]:
    from nmsm.io.osimx import read_osimx
    from nmsm.io.storage import read_storage, strip_load_suffix

    osimx = read_osimx(next(results.glob("*_mtp.osimx")))
    peaks = _trial_activation_peaks(truth_dir, truth)
    out: list[Check] = []
    model = read_storage(next((results / "modelMoments").glob("*_modelMoments.sto")))
    measured = read_storage(next((results / "Analysis" / "inverseDynamicsJointMoments").glob("*.sto")))
    for label in measured.labels:
        name = strip_load_suffix(label)
        column = next((c for c in model.labels if strip_load_suffix(c) == name), None)
        if column is None:
            continue
        rms = float(np.sqrt(np.mean((model.column(column) - measured.column(label)) ** 2)))
        out.append(Check("MTP", f"{name} moment fit RMS", 0.0, rms, rms, 3.0, "N m", rms <= 3.0))
    activations = read_storage(next((results / "muscleActivations").glob("*.sto")))
    sim = np.load(truth_dir / "simulation.npz")
    order = truth["muscle_order"]
    true_a = np.column_stack([np.interp(activations.time, sim["time"], sim["a"][:, k]) for k in range(len(order))])
    rms = float(np.sqrt(np.mean((np.column_stack([activations.column(m) for m in order]) - true_a) ** 2)))
    out.append(Check("MTP", "activations RMS vs truth", 0.0, rms, rms, None, "-", None,
                     "reported: EMG scale and nonlinearity trade off in the moment fit"))
    for name, true in truth["muscles"].items():
        found = osimx.muscles.get(name)
        if found is None:
            continue
        active = peaks[name] > ACTIVE
        note = "" if active else f"peak activation {peaks[name]:.2f}: reported only"
        # activation parameters: judged for the active muscles only
        rows = [
            ("electromechanical delay", true["delay"], 0.1 * found.electromechanical_delay, 0.015, "s", False),
            ("activation time constant", true["activation_time_constant"], 0.01 * found.activation_time_constant,
             0.005, "s", False),
            ("activation nonlinearity", true["nonlinearity"], found.activation_nonlinearity_constant, None, "-", False),
            ("EMG scale factor", true["emg_scale"], found.emg_scale_factor, None, "-", True),
        ]
        for quantity, t, r, tol, unit, relative in rows:
            if r is None:
                continue
            out.append(_check("MTP", f"{name} {quantity}", t, r, tol if active else None,
                              "relative" if relative else unit, relative=relative, note=note))
        # lengths: judged for every muscle (MTLI fits them to the passive trials)
        for quantity, t, r in (("optimal fiber length", true["optimal_fiber_length"], found.optimal_fiber_length),
                               ("tendon slack length", true["tendon_slack_length"], found.tendon_slack_length)):
            out.append(_check("MTP", f"{name} {quantity}", t, r, LENGTH_TOLERANCE, "relative", relative=True))
    return out


# ------------------------------------------------------------------------------------ NCP
def exact_nmf_similarity(truth: dict[str, Any], truth_dir: Path) -> np.ndarray:
    """Cosine similarity with the true synergy vectors of a factorization of the *true*
    activations over the trial (rank S, as the subject was designed): what the best possible
    data determine. The factorization reproduces the activations to 0.5 % and still finds
    other vectors: non-negative factorizations of one trial are not unique."""
    from nmsm.examples.subject_simulation import _nmf
    from nmsm.examples.synthetic_ncp import matched_cosine_similarity

    sim = np.load(truth_dir / "simulation.npz")
    window = (sim["time"] >= truth["trial_window"][0]) & (sim["time"] <= truth["trial_window"][1])
    true = np.asarray(truth["synergy_weights"])
    _, weights = _nmf(sim["a"][window][::10], true.shape[0])
    return matched_cosine_similarity(weights, true)


def ncp_checks(truth: dict[str, Any], truth_dir: Path, results: Path, mtp_results: Path | None = None) -> list[Check]:
    """NCP's synergy activations ``c W`` against the activations it was given (MTP's) and
    against the truth; the synergy vectors are reported with what an exact factorization of
    the true activations finds (:func:`exact_nmf_similarity`): they are not identifiable."""
    from nmsm.examples.synthetic_ncp import matched_cosine_similarity
    from nmsm.io.storage import read_storage

    order = truth["muscle_order"]
    table = read_storage(results / "synergyWeights.sto")
    estimated = np.column_stack([table.column(m) for m in order])
    true = np.asarray(truth["synergy_weights"])
    similarity = matched_cosine_similarity(estimated, true)
    exact = exact_nmf_similarity(truth, truth_dir)
    basis, _ = np.linalg.qr(estimated.T)
    out = []
    for k, value in enumerate(similarity):
        out.append(Check("NCP", f"synergy {k + 1} cosine similarity", 1.0, float(value), float(value - 1.0), None, "-",
                         None, f"not identifiable: an exact factorization of the true activations gives {exact[k]:.2f}"))
    for k, w in enumerate(true):
        projection = basis @ (basis.T @ w)
        cosine = float(projection @ w / max(np.linalg.norm(projection) * np.linalg.norm(w), 1e-300))
        out.append(Check("NCP", f"synergy {k + 1} in the recovered span (cosine)", 1.0, cosine, cosine - 1.0, None, "-",
                         None, "the span of the vectors is what the activations determine"))
    commands = read_storage(next(results.glob("*_synergyCommands.sto")))
    found = commands.data @ estimated  # (frames, muscles): the synergies' activations c W
    sim = np.load(truth_dir / "simulation.npz")
    true_a = np.column_stack([np.interp(commands.time, sim["time"], sim["a"][:, k]) for k in range(len(order))])
    if mtp_results is not None and (mtp_results / "muscleActivations").is_dir():
        given = read_storage(next((mtp_results / "muscleActivations").glob("*.sto")))
        given_a = np.column_stack([np.interp(commands.time, given.time, given.column(m)) for m in order])
        rms = float(np.sqrt(np.mean((found - given_a) ** 2)))
        out.append(Check("NCP", "c W vs MTP's activations (its input) RMS", 0.0, rms, rms, 0.02, "-", rms <= 0.02))
    rms = float(np.sqrt(np.mean((found - true_a) ** 2)))
    out.append(Check("NCP", "c W vs true activations RMS", 0.0, rms, rms, 0.03, "-", rms <= 0.03))
    return out


# ------------------------------------------------------------------------------------ GCP
def gcp_checks(truth: dict[str, Any], results: Path) -> list[Check]:
    from nmsm.io.osimx import read_osimx

    surface = read_osimx(next(results.glob("*_gcp.osimx"))).contact_surfaces[-1]
    contact = truth["contact"]
    out = [
        _check("GCP", "resting spring length", contact["resting_spring_length"], surface.resting_spring_length, 0.15,
               "relative", relative=True),
        _check("GCP", "dynamic friction coefficient", contact["dynamic_friction_coefficient"],
               surface.dynamic_friction_coefficient, 0.10, "relative", relative=True),
        _check("GCP", "viscous friction coefficient", contact["viscous_friction_coefficient"],
               surface.viscous_friction_coefficient, None, "relative", relative=True),
        _check("GCP", "damping factor", contact["damping_factor"], surface.damping_factor, None, "relative",
               relative=True),
    ]
    true_k = {s["name"]: s["spring_constant"] for s in contact["springs"]}
    pairs = [(true_k[s.name], s.spring_constant) for s in surface.springs if s.name in true_k]
    if pairs:
        t, r = np.array(pairs).T
        rms = float(np.sqrt(np.mean(((r - t) / t) ** 2)))
        out.append(Check("GCP", f"spring constants ({len(pairs)}) RMS relative error", 0.0, rms, rms, 0.30,
                         "relative", rms <= 0.30))
    errors = _gcp_reaction_errors(results)
    for name, value in errors.items():
        limit = 5.0 if name.startswith("F") else 1.0
        out.append(Check("GCP", f"ground reaction {name} RMS", 0.0, value, value, limit,
                         "N" if name.startswith("F") else "N m", value <= limit))
    return out


def _gcp_reaction_errors(results: Path) -> dict[str, float]:
    from nmsm.io.storage import read_storage

    optimized = next(results.glob("*_optimizedGroundReactions.sto"), None)
    replaced = next(results.glob("*_replacedExperimentalGroundReactions.sto"), None)
    if optimized is None or replaced is None:
        return {}
    a, b = read_storage(optimized), read_storage(replaced)
    return {label: float(np.sqrt(np.mean((a.column(label) - b.column(label)) ** 2)))
            for label in ("Fx", "Fy", "Fz", "Mx", "My", "Mz") if a.has(label) and b.has(label)}


# ------------------------------------------------------------------------------------ treatment
def _motion(folder: Path, trial: str):
    """(time, {coordinate: rad}) of a folder's ``IKData/<trial>.sto``."""
    from nmsm.io.storage import read_storage
    from nmsm.io.trials import find_trial_file

    table = read_storage(find_trial_file(folder / "IKData", trial))
    factor = np.pi / 180.0 if table.in_degrees else 1.0
    return table.time, {label: table.column(label) * factor for label in table.labels}


def treatment_checks(truth: dict[str, Any], to: Path | None, vo: Path | None, do: Path | None,
                     trial: str) -> list[Check]:
    """TO's tracking of the experimental joint angles (``Analysis/<trial>_modeledPositions``
    vs ``_trackedPositions``, 3 deg RMS); the changes VO and DO make (on normalized time),
    reported."""
    out: list[Check] = []
    coordinates = truth["coordinates"]
    if to is not None:
        from nmsm.io.storage import read_storage

        modeled = read_storage(to / "Analysis" / f"{trial}_modeledPositions.sto")
        tracked = read_storage(to / "Analysis" / f"{trial}_trackedPositions.sto")
        for c in coordinates:
            if modeled.has(c) and tracked.has(c):
                error = modeled.column(c) - tracked.column(c)
                rms = float(np.sqrt(np.mean(error**2)) * (1.0 if modeled.in_degrees else 180.0 / np.pi))
                out.append(Check("TO", f"{c} tracking RMS", 0.0, rms, rms, 3.0, "deg", rms <= 3.0))
    previous = None
    for stage, folder in (("TO", to), ("VO", vo), ("DO", do)):
        if folder is None or not (folder / "IKData").is_dir():
            continue
        t, q = _motion(folder, trial)
        s = (t - t[0]) / (t[-1] - t[0])
        if previous is not None:
            for c in coordinates:
                if c in q and c in previous[1]:
                    base = np.interp(s, previous[0], previous[1][c])
                    change = float(np.degrees(np.sqrt(np.mean((q[c] - base) ** 2))))
                    out.append(Check(stage, f"{c} change vs {previous[2]} (RMS)", 0.0, change, change, None, "deg",
                                     None, "predicted effect" if stage == "DO" else "verification"))
        previous = (s, q, stage)
    return out


# ------------------------------------------------------------------------------------ report
def format_checks(checks: Sequence[Check]) -> str:
    """A plain-text table of ``checks``."""
    lines = [f"{'stage':<6s} {'quantity':<48s} {'truth':>11s} {'recovered':>11s} {'error':>10s} {'tolerance':>10s}  "]
    for c in checks:
        tolerance = "" if c.tolerance is None else f"{c.tolerance:.3g}"
        verdict = {True: "ok", False: "OUT", None: "-"}[c.ok]
        unit = "" if c.unit in ("-", "relative") else f" {c.unit}"
        error = f"{100 * c.error:+.1f}%" if c.unit == "relative" else f"{c.error:+.3g}"
        lines.append(f"{c.stage:<6s} {c.quantity:<48s} {c.truth:11.4g} {c.recovered:11.4g} {error:>10s} "
                     f"{tolerance:>10s}  {verdict}{unit}{('  (' + c.note + ')') if c.note else ''}")
    return "\n".join(lines)


def summary(checks: Sequence[Check]) -> dict[str, tuple[int, int]]:
    """Per stage: (judged checks within tolerance, judged checks)."""
    out: dict[str, tuple[int, int]] = {}
    for c in checks:
        if c.ok is None:
            continue
        good, total = out.get(c.stage, (0, 0))
        out[c.stage] = (good + int(c.ok), total + 1)
    return out

"""Benchmark: Neural Control Personalization of patient 3, both legs and trunk, symmetry on.

148 muscles (90 with MTP activations), 17 tracked coordinates, 2 trials of 101 frames,
6 + 6 synergies with shared (mirrored) vectors: 444 vector weights + 504 command nodes.
Settings: ``ncp/patient3_bilateral_trials1to3/newNCPSettingsFile.xml`` (2023 schema, all
five NCP terms), results in a temporary folder.

Measures (``time.perf_counter``): the whole ``run_settings`` (reading, NMF start, problem,
IPOPT with the structured exact Hessian, normalization, result files), best of
``--repeats``; IPOPT's own time and iterations; the machine's load average (the numbers
scale with it on a shared machine). Prints the per-coordinate moment RMS.

``--free-bound`` also prints the moment RMS reachable without synergies: each frame's
activations free in [0, 1], fitted to the ID moments by bounded linear least squares
(the muscle model is linear in activation), a lower bound for any synergy solution.

``--free-bound`` also prints the best any activations can do *at the settings' weights*:
each frame's activations free in [0, 1] minimizing the settings' moment-tracking,
activation-tracking and activation-minimization terms (grouped terms left out). Synergies only restrict that set,
so this is where the settings' weights put the trade-off before any synergy constraint.
It also prints the moment RMS of the MTP activations themselves (other muscles at 0).

``--sweep`` also runs the activation-tracking allowable error 0.01 / 0.02 / 0.03 / 0.05
with and without bilateral symmetry (settings rewritten into the temporary folder) and
prints the moment-RMS / activation-RMS trade-off.

    python benchmarks/bench_ncp.py [--repeats 3] [--sweep] [--free-bound]
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
import warnings
from pathlib import Path

from lxml import etree

import numpy as np
from scipy.optimize import lsq_linear

from nmsm.tools.ncp.forces import moment_gains
from nmsm.tools.ncp.run import run_settings

SHARED = Path(os.environ.get("NMSM_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
FOLDER = SHARED / "ncp" / "patient3_bilateral_trials1to3"
SETTINGS = FOLDER / "newNCPSettingsFile.xml"


def _variant(target: Path, activation_error: str) -> Path:
    """The settings with absolute paths and another activation-tracking allowable error."""
    tree = etree.parse(str(SETTINGS))
    root = tree.getroot()
    for tag in ("input_model_file", "data_directory", "mtp_results_directory"):
        element = root.find(f".//{tag}")
        element.text = str(FOLDER / element.text.strip())
    for term in root.iter("RCNLCostTerm"):
        if term.findtext("type") == "activation_tracking":
            term.find("max_allowable_error").text = activation_error
    tree.write(str(target))
    return target


def trial_gains(run) -> list:
    """Per trial ``(trial, MomentGains)`` of the run's muscles (computed once, used by the bounds)."""
    inputs = run.setup.inputs
    return [(trial, moment_gains(trial, inputs.muscles, inputs.v_max_factor)) for trial in inputs.trials]


def free_activation_moment_rms(gains: list) -> np.ndarray:
    """Moment RMS per coordinate (N·m) with each frame's activations free in [0, 1] (no synergies)."""
    errors = []
    for trial, g in gains:
        for p in range(trial.n_points):
            target = trial.moments[p] - g.passive[p]
            errors.append(g.active[p] @ lsq_linear(g.active[p], target, bounds=(0.0, 1.0)).x - target)
    return np.sqrt(np.mean(np.square(errors), axis=0))


def _term(run, kind: str):
    """The enabled term of ``kind`` in the run's settings."""
    for term in run.setup.terms:
        if getattr(term, "type", None) == kind:
            return term
    raise LookupError(f"no enabled '{kind}' term in the settings")


def settings_weight_bound(run, gains: list) -> tuple[np.ndarray, float]:
    """Per-coordinate moment RMS (J,) N·m and pooled activation RMS of each frame's
    activations free in [0, 1] minimizing the settings' moment-tracking, activation-tracking
    and activation-minimization terms (each term ``mean((raw / e)**2)`` as in the cost)."""
    inputs = run.setup.inputs
    e_moment = _term(run, "moment_tracking").max_allowable_error
    e_tracking = _term(run, "activation_tracking").max_allowable_error
    minimization = _term(run, "activation_minimization")
    tracked, untracked = list(inputs.mtp_indices), list(inputs.other_indices)
    tracking_weight = 1.0 / (e_tracking * np.sqrt(len(tracked)))
    minimum_weight = 1.0 / (minimization.max_allowable_error * np.sqrt(max(len(untracked), 1)))
    moment_weight = 1.0 / (e_moment * np.sqrt(len(inputs.coordinates)))
    select = np.eye(inputs.layout.n_muscles)
    rows = np.vstack([select[tracked] * tracking_weight, select[untracked] * minimum_weight])
    moment_errors, activation_errors = [], []
    for trial, g in gains:
        for p in range(trial.n_points):
            target = trial.moments[p] - g.passive[p]
            rhs = np.concatenate([target * moment_weight, trial.mtp_activations[p] * tracking_weight,
                                  np.full(len(untracked), minimization.error_center * minimum_weight)])
            x = lsq_linear(np.vstack([g.active[p] * moment_weight, rows]), rhs, bounds=(0.0, 1.0)).x
            moment_errors.append(g.active[p] @ x - target)
            activation_errors.append(x[tracked] - trial.mtp_activations[p])
    return np.sqrt(np.mean(np.square(moment_errors), axis=0)), float(np.sqrt(np.mean(np.square(activation_errors))))


def mtp_activation_moment_rms(run, gains: list) -> np.ndarray:
    """Per-coordinate moment RMS (J,) N·m of the MTP activations as they are, other muscles at 0."""
    tracked = list(run.setup.inputs.mtp_indices)
    errors = []
    for trial, g in gains:
        activations = np.zeros((trial.n_points, run.setup.inputs.layout.n_muscles))
        activations[:, tracked] = trial.mtp_activations
        errors.append(g.moments(activations) - trial.moments)
    return np.sqrt(np.mean(np.square(np.vstack(errors)), axis=0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--sweep", action="store_true", help="also the activation-error / symmetry trade-off")
    parser.add_argument("--free-bound", action="store_true", help="also the moment RMS with free activations")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    best = None
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.repeats):
            load = os.getloadavg()[0]
            start = time.perf_counter()
            run = run_settings(SETTINGS, results_directory=Path(tmp) / f"run{k}", enforce_bilateral_symmetry=True,
                               print_level=0)
            wall = time.perf_counter() - start
            print(f"run {k + 1}: wall {wall:.1f} s (IPOPT {run.solver.wall_time:.1f} s, {run.solver.iterations} iterations,"
                  f" {run.solver.status}); load average {load:.2f} on {os.cpu_count()} cores")
            if best is None or wall < best[0]:
                best = (wall, run)
        assert best is not None
        wall, run = best
        m = run.metrics
        print(f"\nbest wall time {wall:.1f} s (target <= 120 s); cost {run.costs['total']:.4f}")
        print("| coordinate | moment RMS (N·m) |\n|---|---|")
        for c, v in zip(m.coordinates, m.moment_rms):
            print(f"| {c} | {v:.3f} |")
        print(f"| mean | {m.mean_moment_rms:.3f} |")
        print(f"activation RMS (90 MTP muscles) {m.activation_rms_pooled:.4f}, VAF {100 * m.activation_vaf:.2f} %")
        if args.free_bound:
            gains = trial_gains(run)
            free = free_activation_moment_rms(gains)
            print(f"free activations in [0, 1] (no synergies): mean moment RMS {free.mean():.4f} N·m, "
                  f"largest {free.max():.4f} N·m")
            mtp = mtp_activation_moment_rms(run, gains)
            print(f"MTP activations as they are (other muscles 0): mean moment RMS {mtp.mean():.2f} N·m, largest "
                  f"{mtp.max():.2f} N·m ({m.coordinates[int(np.argmax(mtp))]})")
            bound, activation = settings_weight_bound(run, gains)
            print(f"free activations at the settings' weights (no synergies): mean moment RMS {bound.mean():.2f} N·m, "
                  f"activation RMS {activation:.4f}")
        if args.sweep:
            print("\n| activation e | symmetry | iterations | wall s | cost | mean moment RMS N·m | activation RMS |")
            print("|---|---|---|---|---|---|---|")
            for error in ("0.01", "0.02", "0.03", "0.05"):
                settings = _variant(Path(tmp) / f"settings_{error}.xml", error)
                for symmetric in (True, False):
                    start = time.perf_counter()
                    r = run_settings(settings, results_directory=Path(tmp) / f"sweep_{error}_{symmetric}",
                                     enforce_bilateral_symmetry=symmetric, print_level=0)
                    print(f"| {error} | {'on' if symmetric else 'off'} | {r.solver.iterations} | "
                          f"{time.perf_counter() - start:.1f} | {r.costs['total']:.4f} | {r.metrics.mean_moment_rms:.3f} | "
                          f"{r.metrics.activation_rms_pooled:.4f} |")


if __name__ == "__main__":
    main()

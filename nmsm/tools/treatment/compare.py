"""Score another solution (e.g. the original MATLAB pipeline's) in our problem, and compare.

:func:`score_solution` builds the problem of a settings file and evaluates it - cost per
term, constraint violations - at the solution stored in a results folder (its
``<trial>_states.sto``, ``_accelerations.sto``, controls, synergy weights), without
solving. References (tracked data, initial controls) stay those of the settings file.

:func:`tracking_rms` (:mod:`nmsm.tools.treatment.summary`'s) gives, per tracking term, the RMS
over the collocation points of its error (e.g. q_exp - q in rad, τ_exp - τ in N·m).

:func:`legacy_solution_folder` writes a schema-0.1.0 solution (``statesSolution.sto``,
``controlSolution.sto`` of the 2023 toy-arm examples) in the current results layout, so it
can be scored or used as an initial guess.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.tools.treatment.outcome import TreatmentRun
from nmsm.tools.treatment.run import run_settings
from nmsm.tools.treatment.summary import tracking_rms


def score_solution(settings_file: str | os.PathLike[str], solution_directory: str | os.PathLike[str],
                   **options: Any) -> TreatmentRun:
    """Evaluate ``settings_file``'s problem at the solution in ``solution_directory``."""
    return run_settings(settings_file, guess_directory=solution_directory, evaluate_only=True, **options)


def legacy_solution_folder(states_file: str | os.PathLike[str], controls_file: str | os.PathLike[str],
                           target: str | os.PathLike[str], trial: str, torque_coordinates: list[str]) -> Path:
    """Schema-0.1.0 solution files -> ``<trial>_states.sto``, ``_accelerations.sto``,
    ``_torqueControls.sto`` in ``target``.

    ``states_file`` has ``<c>``, ``<c>_u``, ``<c>_dudt`` per state coordinate ``c`` (rad,
    rad/s, rad/s²); ``controls_file`` has ``torqueControl<i>`` (N·m) for the i-th (1-based)
    coordinate of ``torque_coordinates`` (the old ``<coordinate_list>``). Jerk controls
    (columns named like coordinates) are not carried over.
    """
    from nmsm.errors import InputError
    from nmsm.io.storage import read_storage, table_from_columns, write_storage

    states, controls = read_storage(states_file), read_storage(controls_file)
    coordinates = [c for c in states.labels if states.has(f"{c}_u") and states.has(f"{c}_dudt")]
    if not coordinates:
        raise InputError("no '<coordinate>', '<coordinate>_u', '<coordinate>_dudt' column triple",
                         file=states_file, expected="a 0.1.0 statesSolution.sto")
    target = Path(target)
    target.mkdir(parents=True, exist_ok=True)
    write_storage(target / f"{trial}_states.sto", table_from_columns(
        states.time, {**{c: states.column(c) for c in coordinates},
                      **{f"{c}_u": states.column(f"{c}_u") for c in coordinates}}))
    write_storage(target / f"{trial}_accelerations.sto",
                  table_from_columns(states.time, {c: states.column(f"{c}_dudt") for c in coordinates}))
    torques = {}
    for i, c in enumerate(torque_coordinates, start=1):
        label = f"torqueControl{i}"
        if not controls.has(label):
            raise InputError(f"no column '{label}' for torque-controlled coordinate '{c}'", file=controls_file,
                             expected=f"torqueControl1..{len(torque_coordinates)}")
        torques[c] = controls.column(label)
    write_storage(target / f"{trial}_torqueControls.sto", table_from_columns(controls.time, torques))
    return target


#: RMS below which a tracking error counts as matched (issue 8): 0.05 deg, 0.5 N·m
ANGLE_FLOOR = float(np.radians(0.05))
MOMENT_FLOOR = 0.5


def rms_floor(run: TreatmentRun, label: str) -> float:
    """Floor of the RMS criterion for the tracking term ``label`` (``type:name``): 0.05 deg for
    rotational coordinates, 0.5 N·m for loads and torque controls, 0 otherwise (speeds,
    activations and synergy commands have no floor)."""
    kind, _, name = label.partition(":")
    model = run.prepared.model
    if kind == "generalized_coordinate_tracking" and name in model.coordinate_names:
        return ANGLE_FLOOR if model.is_rotational(name) else 0.0
    if kind == "inverse_dynamics_load_tracking":
        return MOMENT_FLOOR
    if kind == "controller_tracking" and name in model.coordinate_names:
        return MOMENT_FLOOR
    return 0.0


def max_constraint_violation(run: TreatmentRun) -> dict[str, float]:
    """Worst violation per constraint block (scaled units, see diagnosis) above 1e-6."""
    return {c.name: c.max_violation for c in run.solution.constraints if c.max_violation > 1e-6}


@attrs.frozen
class Comparison:
    """Our run against another solution scored in our problem."""

    ours: TreatmentRun
    theirs: TreatmentRun

    @property
    def cost_ratio(self) -> float:
        return self.ours.cost / self.theirs.initial_cost if self.theirs.initial_cost > 0 else float("inf")

    def rms(self) -> dict[str, tuple[float, float]]:
        a, b = tracking_rms(self.ours), tracking_rms(self.theirs)
        return {k: (a[k], b.get(k, float("nan"))) for k in a}

    def rms_failures(self) -> dict[str, tuple[float, float, float]]:
        """Tracking terms with RMS > max(1.1 x theirs, floor): label -> (ours, theirs, floor)."""
        out = {}
        for label, (a, b) in self.rms().items():
            floor = rms_floor(self.ours, label)
            if not a <= max(1.1 * b, floor):
                out[label] = (a, b, floor)
        return out

    def report(self) -> str:
        lines = [
            f"ours: {self.ours.solution.status}, {self.ours.solution.iterations} iterations, "
            f"{self.ours.solution.wall_time:.1f} s, cost {self.ours.cost:.6g}",
            f"theirs scored in our problem: cost {self.theirs.initial_cost:.6g} (ratio ours/theirs {self.cost_ratio:.3f})",
        ]
        violations = max_constraint_violation(self.theirs)
        if violations:
            lines.append("  theirs violates: " + ", ".join(f"{k} {v:.3g}" for k, v in violations.items()))
        for label, (a, b) in self.rms().items():
            lines.append(f"  RMS {label:<56s} ours {a:.4g}  theirs {b:.4g}")
        return "\n".join(lines)

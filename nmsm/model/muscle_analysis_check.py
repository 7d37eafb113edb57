"""``nmsm muscle-analysis`` against OpenSim's MuscleAnalysis on any model, over a gait motion.

:func:`gait_motion` makes a motion for a model: coordinates named as in a gait trial
(the RCNL/Rajagopal family) follow the trial; the others swing smoothly within their
ranges; locked coordinates stay at their defaults. :func:`compare_with_opensim` runs both
analyses on it (OpenSim through the bridge) and returns per-muscle RMS differences.
Used by ``benchmarks/check_models_against_opensim.py --muscles`` and the tests.

Units: m, rad (degrees only in the motion file handed to OpenSim).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.io.storage import Table, read_storage, write_storage

#: amplitude of the swing of coordinates the gait trial lacks (fraction of the range; rad cap; m)
SWING_FRACTION, SWING_MAX_ANGLE, SWING_TRANSLATION = 0.3, np.radians(40.0), 0.02


def gait_motion(model: Any, gait: Table) -> Table:
    """A motion ``(n, n_q)`` in the model's coordinates at the times of ``gait`` (in degrees
    when ``gait`` is): columns of ``gait`` that name a coordinate (negated where the model
    counts the other way, e.g. gait2392's knee flexion; none where neither sign keeps most
    frames within the range), a sine over the other unlocked independent coordinates,
    defaults for locked ones; dependent coordinates left to their couplers."""
    time = gait.time
    phase = 2.0 * np.pi * (time - time[0]) / max(float(time[-1] - time[0]), 1e-9)
    labels, columns = [], []
    for k, c in enumerate(model.coordinates):
        if c.name in model.coupled_coordinates:
            continue
        rotational = c.motion_type == "rotational"
        degrees = rotational and gait.in_degrees
        values = _gait_column(gait, c, degrees) if c.name in gait.labels and not c.locked else None
        if values is None:
            lower, upper = c.range
            centre = c.default_value if c.locked else 0.5 * (lower + upper)
            if rotational:
                amplitude = min(SWING_FRACTION * (upper - lower), SWING_MAX_ANGLE)
            else:
                centre, amplitude = c.default_value, SWING_TRANSLATION
            values = centre + (0.0 if c.locked else amplitude) * np.sin(phase + 0.7 * k)
            values = np.degrees(values) if degrees else values
        labels.append(c.name)
        columns.append(values)
    return Table(time=time.copy(), labels=tuple(labels), data=np.column_stack(columns), in_degrees=gait.in_degrees,
                 name="Coordinates")


def _gait_column(gait: Table, coordinate: Any, degrees: bool) -> np.ndarray | None:
    """``gait``'s column of ``coordinate``, or its negation, whichever keeps more frames within the
    coordinate's range; None when that is not most of them."""
    values = gait.column(coordinate.name)
    lower, upper = np.degrees(coordinate.range) if degrees else coordinate.range
    inside = [int(np.sum((v >= lower) & (v <= upper))) for v in (values, -values)]
    best = int(np.argmax(inside))
    if inside[best] < 0.5 * values.size:
        return None
    return values if best == 0 else -values


@attrs.frozen
class MuscleAnalysisComparison:
    """Per-muscle RMS differences (m) over frames; ``moment_arm_rms`` is the worst over the
    coordinates, ``worst_coordinate`` names it; muscles OpenSim's MuscleAnalysis does not
    report (declared outside the ForceSet) are listed in ``unreported``."""

    muscles: tuple[str, ...]
    length_rms: np.ndarray
    moment_arm_rms: np.ndarray
    worst_coordinate: tuple[str, ...]
    sources: dict[str, str]
    unreported: tuple[str, ...]

    def worst(self) -> tuple[str, float, str]:
        """(muscle, moment-arm RMS m, coordinate) of the worst muscle (``("", 0.0, "")`` when
        OpenSim reports none)."""
        if not self.muscles:
            return "", 0.0, ""
        k = int(np.argmax(self.moment_arm_rms))
        return self.muscles[k], float(self.moment_arm_rms[k]), self.worst_coordinate[k]


def compare_with_opensim(model_file: str | os.PathLike[str], motion: Table, folder: str | os.PathLike[str], *,
                         bridge: Any = None, model: Any = None) -> MuscleAnalysisComparison:
    """Run nmsm's and OpenSim's muscle analyses of ``motion`` and compare them (files in ``folder``)."""
    from nmsm.model import load_model
    from nmsm.model.muscle_analysis import analyze_motion

    if bridge is None:
        from nmsm.opensim_bridge import get_bridge

        bridge = get_bridge()
    model = model if model is not None else load_model(model_file)
    folder = Path(folder).resolve()
    folder.mkdir(parents=True, exist_ok=True)
    motion_file = write_storage(folder / "motion.mot", motion, name="Coordinates")
    ours = analyze_motion(model_file, motion, model=model, bridge=bridge)
    spanned = [c for k, c in enumerate(ours.coordinates)
               if c not in model.coupled_coordinates and np.abs(ours.moment_arms[:, :, k]).max() > 0.0]
    bridge.call("run_muscle_analysis", model=str(Path(model_file).resolve()), coordinates_file=str(motion_file),
                results_directory=str(folder), name="check", moment_arm_coordinates=spanned or ["all"])
    lengths = read_storage(folder / "check_MuscleAnalysis_Length.sto")
    reported = [m for m in ours.muscles if m in lengths.labels]
    index = [ours.muscles.index(m) for m in reported]
    length_rms = _rms(lengths.data[:, [lengths.labels.index(m) for m in reported]] - ours.lengths[:, index])
    arm_rms = np.zeros((len(reported), max(len(spanned), 1)))
    for k, c in enumerate(spanned):
        arms = read_storage(folder / f"check_MuscleAnalysis_MomentArm_{c}.sto")
        theirs = arms.data[:, [arms.labels.index(m) for m in reported]]
        arm_rms[:, k] = _rms(theirs - ours.moment_arms[:, index, ours.coordinates.index(c)])
    worst = np.argmax(arm_rms, axis=1)
    return MuscleAnalysisComparison(
        muscles=tuple(reported), length_rms=length_rms, moment_arm_rms=arm_rms.max(axis=1),
        worst_coordinate=tuple(spanned[k] if spanned else "" for k in worst),
        sources={m: ours.sources[m] for m in reported},
        unreported=tuple(m for m in ours.muscles if m not in lengths.labels))


def _rms(difference: np.ndarray) -> np.ndarray:
    """RMS over frames (axis 0)."""
    return np.sqrt(np.mean(np.asarray(difference) ** 2, axis=0))

"""MTP result files, as the original writes them (docs/mtp.md).

Into a staging folder (:class:`nmsm.core.results.ResultsDirectory` moves it into place):

* ``<osimxBase|modelBase>_mtp.osimx``: per muscle electromechanical delay (0.1 s),
  activation time constant (0.01 s), nonlinearity, EMG scale factor, optimal fiber length
  and tendon slack length (m), and maximum isometric force (N) when MTLI updated it;
* ``muscleActivations/<trial>_muscleActivations.sto`` and
  ``modelMoments/<trial>_modelMoments.sto`` (with Synergy Extrapolation: the SynX ones);
* ``Analysis/<quantity>/<trial>_<quantity>.sto`` for ``muscleExcitations``,
  ``muscleActivations``, ``muscleExcitationsSynx``, ``muscleActivationsSynx``,
  ``normalizedFiberLengths``, ``modelJointMoments``, ``modelJointMomentsSynx``,
  ``inverseDynamicsJointMoments``, ``passiveForcesModel`` (``F0 f_P cos alpha``),
  ``totalMuscleForces`` (fiber, ``F0 (a f_L f_V + f_P)``), ``activeMuscleForces``
  (``F0 a f_L f_V``), ``passiveMuscleForces`` (``F0 f_P``), ``tendonForces``
  (total times ``cos alpha``), ``passiveJointMomentsExperimental`` /
  ``passiveJointMomentsModeled`` (passive trials, time = frame number as the original);
* ``Analysis/muscleModelParameters/muscleModelParameters.sto``: rows 1..6 = activation
  time constant (0.01 s), nonlinearity, electromechanical delay (0.1 s), EMG scale,
  optimal fiber length and tendon slack length relative to the input model.

Time columns: the ID frames (EMG time without padding). Moments in N m, forces in N.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import SolverError
from nmsm.io.osimx import OsimxModel, OsimxMuscle, write_osimx
from nmsm.io.storage import table_from_columns, write_storage
from nmsm.tools.mtp.evaluation import ModeledValues
from nmsm.tools.mtp.mtli_model import PassiveTrial
from nmsm.tools.mtp.muscles import MuscleParameters
from nmsm.tools.mtp.problem import MtpData, MtpState


def _write(path: Path, time: np.ndarray, labels: Sequence[str], values: np.ndarray) -> None:
    if not np.all(np.isfinite(values)):
        raise SolverError(f"refusing to write non-finite values to {path.name}")
    path.parent.mkdir(parents=True, exist_ok=True)
    write_storage(path, table_from_columns(time, {label: values[:, i] for i, label in enumerate(labels)}, name=path.stem))


def analysis_files(
    stage: Path,
    data: MtpData,
    plain: ModeledValues,
    synx: ModeledValues | None,
    trial_times: Sequence[np.ndarray],
) -> None:
    """The per-trial ``Analysis/`` and root ``muscleActivations/``, ``modelMoments/`` files."""
    muscles = list(data.muscles.names)
    coords = list(data.coordinates)
    cos_alpha = np.cos(data.muscles.pennation_angle)
    pad = data.padding
    for t, trial in enumerate(data.trials):
        time = trial_times[t]
        n = time.size
        name = trial.name
        fiber_total = plain.tendon_force[t] / cos_alpha
        fiber_passive = plain.passive_force[t] / cos_alpha
        per_quantity = {
            "muscleExcitations": (muscles, plain.excitations[t][pad : pad + n]),
            "muscleActivations": (muscles, plain.activations[t]),
            "normalizedFiberLengths": (muscles, plain.normalized_fiber_length[t]),
            "modelJointMoments": (coords, plain.moments[t]),
            "inverseDynamicsJointMoments": (coords, trial.inverse_dynamics_moments),
            "passiveForcesModel": (muscles, plain.passive_force[t]),
            "totalMuscleForces": (muscles, fiber_total),
            "activeMuscleForces": (muscles, fiber_total - fiber_passive),
            "passiveMuscleForces": (muscles, fiber_passive),
            "tendonForces": (muscles, plain.tendon_force[t]),
        }
        if synx is not None:
            per_quantity["muscleExcitationsSynx"] = (muscles, synx.excitations[t][pad : pad + n])
            per_quantity["muscleActivationsSynx"] = (muscles, synx.activations[t])
            per_quantity["modelJointMomentsSynx"] = (coords, synx.moments[t])
        for quantity, (labels, values) in per_quantity.items():
            _write(stage / "Analysis" / quantity / f"{name}_{quantity}.sto", time, labels, values)
        final = synx if synx is not None else plain
        _write(stage / "muscleActivations" / f"{name}_muscleActivations.sto", time, muscles, final.activations[t])
        _write(stage / "modelMoments" / f"{name}_modelMoments.sto", time, coords, final.moments[t])


def passive_moment_files(
    stage: Path, coordinates: Sequence[str], trials: Sequence[PassiveTrial], modeled: Sequence[np.ndarray]
) -> None:
    """``passiveJointMomentsExperimental`` / ``Modeled`` per passive trial (time = frame number)."""
    for trial, model in zip(trials, modeled):
        frames = np.arange(1, trial.inverse_dynamics_moments.shape[0] + 1, dtype=float)
        for quantity, values in (
            ("passiveJointMomentsExperimental", trial.inverse_dynamics_moments),
            ("passiveJointMomentsModeled", model),
        ):
            _write(stage / "Analysis" / quantity / f"{trial.name}_{quantity}.sto", frames, coordinates, values)


def parameter_file(stage: Path, state: MtpState, final: MuscleParameters, original: MuscleParameters) -> None:
    """``Analysis/muscleModelParameters/muscleModelParameters.sto`` (rows 1..6)."""
    d = state.design
    rows = np.vstack([
        np.asarray(d.activation_time_constant, dtype=float),
        np.asarray(d.activation_nonlinearity, dtype=float),
        np.asarray(d.electromechanical_delay, dtype=float),
        np.asarray(d.emg_scale, dtype=float),
        final.optimal_fiber_length / original.optimal_fiber_length,
        final.tendon_slack_length / original.tendon_slack_length,
    ])
    _write(stage / "Analysis" / "muscleModelParameters" / "muscleModelParameters.sto",
           np.arange(1.0, 7.0), list(final.names), rows)


def osimx_file(
    stage: Path,
    file_name: str,
    model_name: str,
    model_file: str,
    state: MtpState,
    final: MuscleParameters,
    *,
    write_max_isometric_force: bool,
    base: OsimxModel | None = None,
) -> Path:
    """The ``*_mtp.osimx``: RCNLMuscle entries of ``base`` kept, MTP's muscles replaced."""
    d = state.design
    muscles = dict(base.muscles) if base is not None else {}
    for i, name in enumerate(final.names):
        previous = muscles.get(name)
        muscles[name] = OsimxMuscle(
            name=name,
            electromechanical_delay=float(np.asarray(d.electromechanical_delay)[i]),
            activation_time_constant=float(np.asarray(d.activation_time_constant)[i]),
            activation_nonlinearity_constant=float(np.asarray(d.activation_nonlinearity)[i]),
            emg_scale_factor=float(np.asarray(d.emg_scale)[i]),
            optimal_fiber_length=float(final.optimal_fiber_length[i]),
            tendon_slack_length=float(final.tendon_slack_length[i]),
            max_isometric_force=float(final.max_isometric_force[i]) if write_max_isometric_force
            else (previous.max_isometric_force if previous is not None else None),
            extra=previous.extra if previous is not None else (),
        )
    if base is not None:
        model = attrs.evolve(base, muscles=muscles)
    else:
        model = OsimxModel(name=model_name, associated_osim_model=model_file, muscles=muscles)
    path = stage / file_name
    write_osimx(path, model)
    return path

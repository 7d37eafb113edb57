"""Synthetic muscle activations of the full-body gait case: static optimization of ID moments.

The tutorial trial has EMG for 9 right-leg muscles only, so the 86-muscle stress case gets
activations from static optimization (synthetic, not measured): at each frame, with the
muscles' lengths, velocities and moment arms from the muscle analysis and the Hill model of
NCP (:func:`nmsm.tools.ncp.forces.moment_gains`, moments affine in activation),

    minimize  Σ_m a_m²  +  w Σ_j ((Σ_m G_jm a_m + P_j - τ_j) / 1 N·m)²,   a_m ∈ [a_min, 1],

a bounded linear least-squares problem per frame (``scipy.optimize.lsq_linear``). The
moment error is a penalty (weight ``w``) rather than a constraint: some ID moments of the
tutorial trial (e.g. the mtp and subtalar moments) exceed what the muscles can make, and
a penalty still gives the best activations there. :func:`write_activations` writes them in
MTP's layout (``muscleActivations/<trial>.sto``), the input of NCP.

The model's tendon slack lengths (scaled generic values) leave many fibers stretched past
their optimal length along the trial with NCP's rigid-tendon model (ankle passive moments
of -100 to -200 N·m); :func:`tendon_slack_lengths` lengthens a tendon just enough that its
fiber never exceeds ``MAX_FIBER_LENGTH`` optimal lengths in the trial, a stand-in for
muscle-tendon length initialization. The lengths go to the case's ``.osimx`` (as MTP's
would), so NCP and the treatment tools use the same muscles.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.io.storage import Table, write_storage
from nmsm.model import load_model
from nmsm.tools.mtp.data import load_trial
from nmsm.tools.mtp.muscles import MuscleParameters
from nmsm.tools.ncp.forces import moment_gains
from nmsm.tools.ncp.inputs import NcpTrial

#: weight of a 1 N·m moment error against one muscle at full activation
MOMENT_WEIGHT = 10.0
MINIMUM_ACTIVATION = 0.01
#: longest normalized fiber length (-) :func:`tendon_slack_lengths` allows in the trial
MAX_FIBER_LENGTH = 1.0
V_MAX_FACTOR = 10.0


@attrs.frozen
class StaticOptimization:
    """``time`` (P,) s, ``activations`` (P, M), ``moments`` (P, J) ID, ``modeled`` (P, J) N·m."""

    muscles: tuple[str, ...]
    coordinates: tuple[str, ...]
    time: np.ndarray
    activations: np.ndarray
    moments: np.ndarray
    modeled: np.ndarray

    def rms_error(self) -> np.ndarray:
        """(J,) RMS of modeled minus ID moments (N·m)."""
        return np.sqrt(np.mean((self.modeled - self.moments) ** 2, axis=0))


def model_parameters(model_file: str | os.PathLike[str], muscles: Sequence[str]) -> MuscleParameters:
    """Hill parameters of ``muscles`` as the ``.osim`` gives them."""
    model = load_model(model_file)
    ms = [model.muscle(m) for m in muscles]
    return MuscleParameters(tuple(muscles), [m.max_isometric_force for m in ms],
                            [m.optimal_fiber_length for m in ms], [m.tendon_slack_length for m in ms],
                            [m.pennation_angle_at_optimal for m in ms])


def read_trial(data_directory: str | os.PathLike[str], trial: str, coordinates: Sequence[str],
               muscles: Sequence[str]) -> NcpTrial:
    """ID moments and muscle analysis of ``trial`` (``IDData/<trial>.sto``, ``MAData/<trial>/``)."""
    raw = load_trial(data_directory, trial, list(coordinates), list(muscles))
    return NcpTrial(name=trial, time=raw.time, lengths=raw.muscle_tendon_length,
                    velocities=raw.muscle_tendon_velocity, moment_arms=raw.moment_arms,
                    moments=raw.inverse_dynamics_moments)


def tendon_slack_lengths(trial: NcpTrial, parameters: MuscleParameters,
                         max_fiber_length: float = MAX_FIBER_LENGTH) -> np.ndarray:
    """(M,) tendon slack lengths (m): the model's, or longer where the trial's longest
    muscle-tendon length would stretch the fiber past ``max_fiber_length``."""
    longest = np.max(trial.lengths, axis=0)
    needed = longest - max_fiber_length * parameters.optimal_fiber_length * np.cos(parameters.pennation_angle)
    return np.maximum(parameters.tendon_slack_length, needed)


def static_optimization(trial: NcpTrial, parameters: MuscleParameters, coordinates: Sequence[str], *,
                        moment_weight: float = MOMENT_WEIGHT) -> StaticOptimization:
    """Activations of the ``parameters``' muscles reproducing the trial's ID moments of
    ``coordinates`` (the trial's moment columns; module docstring)."""
    from scipy.optimize import lsq_linear

    ncp_trial = trial
    gains = moment_gains(ncp_trial, parameters, V_MAX_FACTOR)
    n_frames, n_muscles = trial.lengths.shape
    root_w = np.sqrt(moment_weight)
    activations = np.zeros((n_frames, n_muscles))
    for p in range(n_frames):
        A = np.vstack([root_w * gains.active[p], np.eye(n_muscles)])
        b = np.concatenate([root_w * (ncp_trial.moments[p] - gains.passive[p]), np.zeros(n_muscles)])
        activations[p] = lsq_linear(A, b, bounds=(MINIMUM_ACTIVATION, 1.0), method="bvls").x
    return StaticOptimization(tuple(parameters.names), tuple(coordinates), np.asarray(trial.time), activations,
                              np.asarray(ncp_trial.moments), gains.moments(activations))


def write_activations(result: StaticOptimization, folder: str | os.PathLike[str], trial: str) -> Path:
    """``<folder>/muscleActivations/<trial>.sto`` (MTP's results layout)."""
    path = Path(folder) / "muscleActivations" / f"{trial}.sto"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_storage(path, Table(time=result.time, labels=result.muscles, data=result.activations),
                  name="muscleActivations")
    return path

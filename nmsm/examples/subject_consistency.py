"""Is the example's data consistent with MTP's model at the true parameters?

:func:`mtp_at_truth` evaluates Muscle-Tendon Personalization's own model chain
(:mod:`nmsm.tools.mtp.model`: delayed EMG spline, BDF2 activation dynamics, nonlinearity,
Hill muscles on the preprocessed muscle-tendon lengths, velocities and moment arms) with
every muscle parameter at its true value, on the preprocessed trial the pipeline hands
MTP, and compares the modeled joint moments with the preprocessed inverse dynamics and the
modeled activations with the simulation's. What remains at the truth is what no MTP
result can beat: inverse dynamics of filtered marker data (about 2.7 N m RMS at the hip)
and activations the activation dynamics cannot reproduce exactly (the simulation's
activations sometimes fall faster than deactivation allows; ``truth.json``
``excitation_clipping``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import attrs
import numpy as np


@attrs.frozen
class TruthFit:
    """MTP's model at the truth on the preprocessed trial.

    ``moments``, ``measured`` (frames, 3) N m (modeled, preprocessed ID), ``activations``,
    ``true_activations`` (frames, M), ``coordinates``, ``muscles`` (names), ``time`` (s).
    """

    time: np.ndarray
    coordinates: tuple[str, ...]
    muscles: tuple[str, ...]
    moments: np.ndarray
    measured: np.ndarray
    activations: np.ndarray
    true_activations: np.ndarray

    @property
    def moment_rms(self) -> np.ndarray:
        """(3,) RMS of modeled minus measured moments (N m) per coordinate."""
        return np.sqrt(np.mean((self.moments - self.measured) ** 2, axis=0))

    @property
    def activation_rms(self) -> np.ndarray:
        """(M,) RMS of modeled minus simulated activations per muscle."""
        return np.sqrt(np.mean((self.activations - self.true_activations) ** 2, axis=0))


def mtp_at_truth(folder: str | Path, data_directory: str | Path, trial: str) -> TruthFit:
    """Evaluate MTP's model at the truth of the subject in ``folder`` (:func:`nmsm.examples.subject.make_subject`)
    on ``data_directory`` (the preprocessing stage's output) for trial ``trial``."""
    from nmsm.examples.subject import read_truth
    from nmsm.model.osim import load_model
    from nmsm.tools.mtp.data import load_trial
    from nmsm.tools.mtp.evaluation import evaluate
    from nmsm.tools.mtp.model import MuscleDesign
    from nmsm.tools.mtp.model_info import muscle_parameters
    from nmsm.tools.mtp.problem import MtpData, MtpState

    folder = Path(folder)
    truth = read_truth(folder / "truth" / "truth.json")
    model = load_model(folder / "truth" / "true.osim")
    names = tuple(truth["muscle_order"])
    coordinates = tuple(truth["coordinates"])
    channels = [truth["muscles"][m]["channel"] for m in names]
    muscles = muscle_parameters(model, names)
    trial_data = load_trial(data_directory, trial, coordinates, names, channels)
    data = MtpData(muscles, coordinates, (trial_data,), np.arange(len(names)))
    rows: dict[str, Any] = {m: truth["muscles"][m] for m in names}
    design = MuscleDesign(
        electromechanical_delay=np.array([10.0 * rows[m]["delay"] for m in names]),
        activation_time_constant=np.array([100.0 * rows[m]["activation_time_constant"] for m in names]),
        activation_nonlinearity=np.array([rows[m]["nonlinearity"] for m in names]),
        emg_scale=np.array([rows[m]["emg_scale"] for m in names]),
        optimal_fiber_length_scale=np.ones(len(names)),
        tendon_slack_length_scale=np.ones(len(names)),
    )
    values, _ = evaluate(data, MtpState(design))
    simulation = np.load(folder / "truth" / "simulation.npz")
    true_a = np.column_stack([np.interp(trial_data.time, simulation["time"], simulation["a"][:, k])
                              for k in range(len(names))])
    return TruthFit(trial_data.time, coordinates, names, values.moments[0], trial_data.inverse_dynamics_moments,
                    values.activations[0], true_a)

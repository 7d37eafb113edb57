"""The synthetic subject's lab recordings, made from its forward simulation.

* :func:`excitations_from_activations`: the neural excitations ``e`` (T, M) that produce the
  simulated activations through the muscles' activation dynamics (inverse of
  ``dn/dt = (c1 e + c2)(e - n)``, ``a = f_A(n)``), clipped to [0, 1] where the activations
  fall faster than deactivation allows;
* :func:`raw_emg`: what the EMG amplifier records: each channel's excitation ``delay``
  seconds *ahead* (EMG precedes force) times a 1 mV-scale gain and a carrier sine
  (80-220 Hz), so that high-pass filtering, rectification and low-pass filtering recover
  the excitation's shape;
* :func:`marker_table`: the model's markers along the motion (m, optionally with noise);
* :func:`ground_reaction`: the springs' resultant as a force plate reports it
  (:func:`nmsm.interop.external_loads.reaction_from_resultant`).

Arrays: time on axis 0; SI units.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from nmsm.interop.external_loads import GroundReaction, reaction_from_resultant
from nmsm.model import hill


def inverse_nonlinearity(activation: np.ndarray, nonlinearity: np.ndarray) -> np.ndarray:
    """Neural activation ``n`` with ``f_A(n) = activation`` (elementwise bisection; ``f_A``
    increases on [0, 1.2])."""
    a = np.asarray(activation, dtype=float)
    low, high = np.zeros_like(a), np.full_like(a, 1.2)
    for _ in range(60):
        mid = 0.5 * (low + high)
        above = hill.activation_nonlinearity(mid, nonlinearity) > a
        high = np.where(above, mid, high)
        low = np.where(above, low, mid)
    return 0.5 * (low + high)


def excitations_from_activations(time: np.ndarray, activation: np.ndarray, time_constant: np.ndarray,
                                 nonlinearity: np.ndarray) -> tuple[np.ndarray, float]:
    """Excitations (T, M) producing ``activation`` (T, M); also the largest excitation that
    had to be clipped into [0, 1] (0 when none did)."""
    n = inverse_nonlinearity(activation, np.asarray(nonlinearity)[None, :])
    rate = np.gradient(n, time, axis=0)
    tau_a = np.asarray(time_constant, dtype=float)[None, :]
    c2 = 1.0 / (hill.DEACTIVATION_RATIO * tau_a)
    c1 = 1.0 / tau_a - c2
    b = c2 - c1 * n
    discriminant = b * b + 4.0 * c1 * (c2 * n + rate)
    excitation = (-b + np.sqrt(np.maximum(discriminant, 0.0))) / (2.0 * c1)
    clipped = np.where(excitation < 0.0, -excitation, np.where(excitation > 1.0, excitation - 1.0, 0.0))
    return np.clip(excitation, 0.0, 1.0), float(clipped.max(initial=0.0))


def raw_emg(time: np.ndarray, excitation: np.ndarray, delays: Sequence[float], out_time: np.ndarray,
            seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Raw EMG (len(out_time), M) in mV and the channel gains (M,): channel ``m`` at time
    ``t`` is ``gain_m * e_m(t + delay_m) * sin(2 pi f_m t + phase_m)``."""
    rng = np.random.default_rng(seed)
    n_channels = excitation.shape[1]
    gains = rng.uniform(0.2, 1.0, n_channels)
    frequencies = np.linspace(80.0, 220.0, n_channels) + rng.uniform(-5, 5, n_channels)
    phases = rng.uniform(0.0, 2 * np.pi, n_channels)
    out = np.zeros((out_time.size, n_channels))
    for m in range(n_channels):
        envelope = np.interp(out_time + delays[m], time, excitation[:, m])
        out[:, m] = gains[m] * envelope * np.sin(2 * np.pi * frequencies[m] * out_time + phases[m])
    return out, gains


def marker_table(casadi_model, names: Sequence[str], time: np.ndarray, q: np.ndarray, noise: float = 0.0,
                 seed: int = 0):
    """:class:`~nmsm.io.trc.MarkerTable` of the model's markers ``names`` at coordinates
    ``q`` (T, n); ``noise``: standard deviation (m) of added Gaussian noise."""
    from nmsm.io.trc import MarkerTable

    function = casadi_model.marker_function(list(names)).map(time.size)
    positions = np.array(function(q.T)).reshape(3, len(names), time.size, order="F").transpose(2, 1, 0)
    if noise > 0:
        positions = positions + np.random.default_rng(seed).normal(scale=noise, size=positions.shape)
    rate = 1.0 / float(np.median(np.diff(time)))
    return MarkerTable(time=time, names=tuple(names), positions=positions, units="mm", data_rate=rate,
                       camera_rate=rate)


def ground_reaction(name: str, body: str, time: np.ndarray, force: np.ndarray, moment: np.ndarray) -> GroundReaction:
    """The force plate's view of the springs' resultant (threshold 5 N vertical)."""
    return reaction_from_resultant(name, body, time, force, moment, floor_height=0.0, threshold=5.0)

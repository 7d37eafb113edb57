"""The arrays NCP works on, independent of files: trials, muscle parameters, groups.

Muscle parameters and muscle groups are MTP's classes (:mod:`nmsm.tools.mtp.muscles`).

Everything is in NCP muscle order (:attr:`SynergyLayout.muscles`, group by group) and
coordinate order (:attr:`NcpInputs.coordinates`). SI units: m, m/s, N, N·m (N for
translational coordinates), radians. Time along axis 0.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np

from nmsm.model import hill
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters
from nmsm.tools.ncp.synergies import SynergyLayout


def _array(value: object) -> np.ndarray:
    arr = np.array(value, dtype=float)
    arr.setflags(write=False)
    return arr


@attrs.frozen
class NcpTrial:
    """One trial's data.

    ``time`` (P,) s; ``lengths`` and ``velocities`` (P, M) muscle-tendon length (m) and
    lengthening velocity (m/s); ``moment_arms`` (P, J, M) (m, or unitless for
    translational coordinates); ``moments`` (P, J) inverse-dynamics loads;
    ``mtp_activations`` (P, K) activations of :attr:`NcpInputs.mtp_muscles` or None.
    ``load_labels`` (J,) are the ID column labels (``<coordinate>_moment``/``_force``).
    """

    name: str
    time: np.ndarray = attrs.field(converter=_array)
    lengths: np.ndarray = attrs.field(converter=_array)
    velocities: np.ndarray = attrs.field(converter=_array)
    moment_arms: np.ndarray = attrs.field(converter=_array)
    moments: np.ndarray = attrs.field(converter=_array)
    mtp_activations: np.ndarray | None = attrs.field(default=None, converter=attrs.converters.optional(_array))
    load_labels: tuple[str, ...] = attrs.field(default=(), converter=tuple)

    def __attrs_post_init__(self) -> None:
        p = self.time.shape[0]
        m = self.lengths.shape[1] if self.lengths.ndim == 2 else -1
        j = self.moments.shape[1] if self.moments.ndim == 2 else -1
        checks = {
            "lengths": (self.lengths.shape, (p, m)),
            "velocities": (self.velocities.shape, (p, m)),
            "moment_arms": (self.moment_arms.shape, (p, j, m)),
            "moments": (self.moments.shape, (p, j)),
        }
        for name, (shape, expected) in checks.items():
            if shape != expected:
                raise ValueError(f"trial '{self.name}': {name} has shape {shape}, expected {expected}")
        if self.mtp_activations is not None and self.mtp_activations.shape[0] != p:
            raise ValueError(f"trial '{self.name}': mtp_activations has {self.mtp_activations.shape[0]} rows, expected {p}")

    @property
    def n_points(self) -> int:
        return int(self.time.shape[0])


@attrs.frozen
class NcpInputs:
    """Everything the NCP optimization needs.

    ``mtp_muscles``: muscles with MTP activations, in NCP muscle order (the columns of every
    trial's ``mtp_activations``). ``activation_groups`` / ``fiber_length_groups``: the
    settings' activation and normalized-fiber-length muscle groups restricted to NCP muscles.
    ``curves``: the force-length-velocity curves' constants (the pipeline's by default).
    """

    layout: SynergyLayout
    coordinates: tuple[str, ...] = attrs.field(converter=tuple)
    trials: tuple[NcpTrial, ...] = attrs.field(converter=tuple)
    muscles: MuscleParameters
    mtp_muscles: tuple[str, ...] = attrs.field(default=(), converter=tuple)
    activation_groups: tuple[MuscleGroup, ...] = attrs.field(default=(), converter=tuple)
    fiber_length_groups: tuple[MuscleGroup, ...] = attrs.field(default=(), converter=tuple)
    v_max_factor: float = 10.0
    curves: hill.MuscleCurves = hill.CURVES

    def __attrs_post_init__(self) -> None:
        m = self.layout.n_muscles
        if tuple(self.muscles.names) != self.layout.muscles:
            raise ValueError("muscle parameters must list the synergy groups' muscles in layout order")
        order = {name: i for i, name in enumerate(self.layout.muscles)}
        unknown = [name for name in self.mtp_muscles if name not in order]
        if unknown:
            raise ValueError(f"mtp_muscles not in the synergy groups: {', '.join(unknown)}")
        positions = [order[name] for name in self.mtp_muscles]
        if positions != sorted(positions):
            raise ValueError("mtp_muscles must follow the NCP muscle order")
        for trial in self.trials:
            if trial.lengths.shape[1] != m or trial.moments.shape[1] != len(self.coordinates):
                raise ValueError(
                    f"trial '{trial.name}' has {trial.lengths.shape[1]} muscles and {trial.moments.shape[1]} "
                    f"coordinates, expected {m} and {len(self.coordinates)}"
                )
            k = 0 if trial.mtp_activations is None else trial.mtp_activations.shape[1]
            if k != len(self.mtp_muscles):
                raise ValueError(f"trial '{trial.name}' has {k} MTP activation columns, expected {len(self.mtp_muscles)}")

    @property
    def mtp_indices(self) -> tuple[int, ...]:
        """Positions of the muscles with MTP activations in the NCP muscle order."""
        order = {name: i for i, name in enumerate(self.layout.muscles)}
        return tuple(order[name] for name in self.mtp_muscles)

    @property
    def other_indices(self) -> tuple[int, ...]:
        """Positions of the muscles without MTP activations."""
        have = set(self.mtp_indices)
        return tuple(i for i in range(self.layout.n_muscles) if i not in have)

    @property
    def has_mtp_activations(self) -> bool:
        return bool(self.mtp_muscles)

    def with_trials(self, trials: Sequence[NcpTrial]) -> NcpInputs:
        return attrs.evolve(self, trials=tuple(trials))

"""A set of synergies: vectors, command nodes and commands per trial, and what they give.

Treatment Optimization and the NCP outputs use the same object: ``weights`` (S, M) is the
block-diagonal matrix of synergy vectors (rows) in NCP muscle order, ``commands`` one
(P, S) array per trial, ``nodes`` the spline nodes they come from (None for commands read
from files).
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import numpy as np

from nmsm.tools.ncp.synergies import SynergyLayout, activations, normalize_by_max_weight


def _readonly(value: object) -> np.ndarray:
    arr = np.array(value, dtype=float)
    arr.setflags(write=False)
    return arr


def _readonly_list(values: Sequence[object]) -> tuple[np.ndarray, ...]:
    return tuple(_readonly(v) for v in values)


@attrs.frozen
class SynergySolution:
    """Synergy vectors and commands.

    ``weights`` (S, M); ``commands`` per trial (P_t, S); ``nodes`` per trial (N, S) or None;
    ``trial_names`` label the trials.
    """

    layout: SynergyLayout
    weights: np.ndarray = attrs.field(converter=_readonly)
    commands: tuple[np.ndarray, ...] = attrs.field(converter=_readonly_list)
    trial_names: tuple[str, ...] = attrs.field(converter=tuple)
    nodes: tuple[np.ndarray, ...] | None = attrs.field(
        default=None, converter=attrs.converters.optional(_readonly_list)
    )

    def __attrs_post_init__(self) -> None:
        s, m = self.layout.n_synergies, self.layout.n_muscles
        if self.weights.shape != (s, m):
            raise ValueError(f"weights have shape {self.weights.shape}, expected ({s}, {m})")
        if len(self.commands) != len(self.trial_names):
            raise ValueError("one command array per trial name is needed")
        for name, c in zip(self.trial_names, self.commands):
            if c.ndim != 2 or c.shape[1] != s:
                raise ValueError(f"commands of trial '{name}' have shape {c.shape}, expected (frames, {s})")

    def activations(self, trial: int) -> np.ndarray:
        """Muscle activations (P, M) of trial ``trial``."""
        return activations(self.weights, self.commands[trial])

    def all_activations(self) -> list[np.ndarray]:
        return [self.activations(t) for t in range(len(self.commands))]

    def normalized(self) -> SynergySolution:
        """The same activations with each synergy vector's largest weight equal to one."""
        weights, commands, factors = normalize_by_max_weight(self.weights, self.commands)
        nodes = None if self.nodes is None else [n * factors[None, :] for n in self.nodes]
        return attrs.evolve(self, weights=weights, commands=commands, nodes=nodes)

    def group_weights(self, group: int) -> np.ndarray:
        """Block (S_g, M_g) of synergy group ``group``."""
        return self.weights[self.layout.synergy_slice(group), self.layout.muscle_slice(group)]

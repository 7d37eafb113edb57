"""Starting synergies for the NCP optimization.

A uniform start (every weight 0.01, every command node 1) makes all synergies of a group
identical, a symmetric point an exact-derivative optimizer never leaves (each synergy
gets the same gradient). As the current MATLAB code does, the start here is the NMF of
the MTP activations when a group has them:

* NMF (:mod:`nmsm.tools.ncp.nmf`) of the group's muscles with MTP activations, frames of
  every trial stacked, gives vectors and commands; with bilateral symmetry both groups'
  activations (mirrored muscle order) are stacked and factorized together;
* weights of the group's muscles without MTP activations start at a fraction
  (:data:`UNTRACKED_WEIGHT_FRACTION`) of the mean tracked weight of each vector;
* groups without (enough) MTP activations start from distinct smooth command bumps
  (one peak per synergy, spread over the cycle) and uniform vectors, so synergies differ;
* each vector is then scaled to the weight-sum constraint (``M_g/100``) and its commands
  inversely, and the commands are fitted by spline nodes (clipped at zero).
"""

from __future__ import annotations

import attrs
import numpy as np

from nmsm.tools.ncp.inputs import NcpInputs
from nmsm.tools.ncp.nmf import nmf
from nmsm.tools.ncp.spline import nodes_from_commands

#: starting weight of a muscle without MTP activations, relative to the vector's mean tracked weight
UNTRACKED_WEIGHT_FRACTION = 0.5
#: mean activation the command bumps of a group without MTP activations start at
DEFAULT_ACTIVATION_LEVEL = 0.05


@attrs.frozen
class SynergyGuess:
    """Free groups' weight blocks (S_g, M_g) in ``layout.free_groups`` order, nodes per trial (N, S)."""

    weight_blocks: tuple[np.ndarray, ...]
    nodes: tuple[np.ndarray, ...]


def _bumps(n_points: int, n_synergies: int, level: float) -> np.ndarray:
    """(n_points, n_synergies) smooth periodic bumps peaking at evenly spread phases."""
    phase = np.linspace(0.0, 1.0, n_points)[:, None]
    centers = (np.arange(n_synergies)[None, :] + 0.5) / n_synergies
    shape = 0.5 + 0.5 * np.cos(2 * np.pi * (phase - centers))
    return level * (0.25 + shape**2)


def _group_guess(
    inputs: NcpInputs, group: int, partner: int | None, partner_map: tuple[int, ...] | None
) -> tuple[np.ndarray, list[np.ndarray], list[np.ndarray] | None]:
    """Weights (S_g, M_g) and commands per trial for ``group`` (and its sharing partner)."""
    layout = inputs.layout
    g = layout.groups[group]
    mslice = layout.muscle_slice(group)
    mtp = set(inputs.mtp_indices)
    tracked = [i for i in range(g.n_muscles) if mslice.start + i in mtp]
    columns = {idx: k for k, idx in enumerate(inputs.mtp_indices)}
    frames = [t.n_points for t in inputs.trials]

    def data_of(group_index: int, muscle_order: list[int]) -> np.ndarray:
        start = layout.muscle_slice(group_index).start
        return np.vstack([t.mtp_activations[:, [columns[start + i] for i in muscle_order]] for t in inputs.trials])

    if partner is not None and partner_map is not None:
        # partner muscle i mirrors this group's muscle partner_map[i]; need partner muscle for each own muscle
        inverse = [0] * g.n_muscles
        for i, j in enumerate(partner_map):
            inverse[j] = i
        partner_start = layout.muscle_slice(partner).start
        tracked = [i for i in tracked if partner_start + inverse[i] in mtp]
    n_syn = g.n_synergies
    weights = np.zeros((n_syn, g.n_muscles))
    if len(tracked) >= n_syn:
        data = data_of(group, tracked)
        if partner is not None and partner_map is not None:
            data = np.vstack([data, data_of(partner, [inverse[i] for i in tracked])])
        result = nmf(data, n_syn, n_starts=4, seed=0)
        weights[:, tracked] = result.weights
        stacked = result.commands
        untracked = [i for i in range(g.n_muscles) if i not in set(tracked)]
        if untracked:
            fill = UNTRACKED_WEIGHT_FRACTION * result.weights.mean(axis=1, keepdims=True)
            weights[:, untracked] = np.maximum(fill, 1e-6)
    else:
        weights[:] = 1.0 + 0.1 * np.cos(np.arange(g.n_muscles)[None, :] + np.arange(n_syn)[:, None])
        # weights of mean one and bumps of mean ~level/S_g: activations ~ level
        weights /= weights.mean(axis=1, keepdims=True)
        level = DEFAULT_ACTIVATION_LEVEL / n_syn
        blocks = [_bumps(p, n_syn, level) for p in frames]
        if partner is not None:
            blocks += [_bumps(p, n_syn, level) for p in frames]
        stacked = np.vstack(blocks)
    # scale each vector to the weight-sum constraint, commands inversely
    sums = weights.sum(axis=1)
    sums = np.where(sums > 0, sums, 1.0)
    ratio = g.weight_sum / sums
    weights *= ratio[:, None]
    stacked = stacked / ratio[None, :]
    splits = np.cumsum(frames)[:-1]
    own = np.split(stacked[: sum(frames)], splits)
    other = np.split(stacked[sum(frames):], splits) if partner is not None else None
    return weights, own, other


def initial_guess(inputs: NcpInputs) -> SynergyGuess:
    """Starting weight blocks and command nodes (see module docstring)."""
    layout = inputs.layout
    commands = [np.zeros((t.n_points, layout.n_synergies)) for t in inputs.trials]
    blocks = []
    partners = {share[0]: (g, share[1]) for g, share in enumerate(layout.shared_from) if share is not None}
    for group in layout.free_groups:
        partner, partner_map = partners.get(group, (None, None))
        weights, own, other = _group_guess(inputs, group, partner, partner_map)
        blocks.append(weights)
        for t, c in enumerate(own):
            commands[t][:, layout.synergy_slice(group)] = c
        if partner is not None and other is not None:
            for t, c in enumerate(other):
                commands[t][:, layout.synergy_slice(partner)] = c
    nodes = tuple(np.maximum(nodes_from_commands(c, layout.n_nodes), 0.0) for c in commands)
    return SynergyGuess(weight_blocks=tuple(blocks), nodes=nodes)

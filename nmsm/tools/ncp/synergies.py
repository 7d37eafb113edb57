"""Synergy parameterization: groups, block-diagonal synergy vectors, commands, activations.

Notation (docs/ncp.md): muscles are ordered group by group; group ``g`` has ``M_g``
muscles and ``S_g`` synergies. The synergy vectors form a block-diagonal weight matrix
``W`` (S, M) whose rows are the vectors (one block ``W_g`` (S_g, M_g) per group); the
synergy commands of a trial are ``C`` (P, S) with P frames. Muscle activations are

    a (P, M) = C @ W                               (same as MATLAB's ``a = Wᵀ·Cᵀ`` transposed)

All functions accept numpy arrays or CasADi matrices (MX/SX/DM) where noted, so the
tool's optimization problem and the post-processing share one implementation. Synergy
names are ``<group>_<k>`` with ``k`` 1-based within the group (the names Treatment
Optimization uses for synergy controls).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import numpy as np

from nmsm.tools.ncp.spline import DEFAULT_NODE_COUNT, interpolation_matrix

#: every synergy vector of group ``g`` sums to ``M_g * WEIGHT_SUM_PER_MUSCLE`` (as the original)
WEIGHT_SUM_PER_MUSCLE = 0.01


def _positive_int(instance: Any, attribute: attrs.Attribute, value: int) -> None:
    if int(value) < 1:
        raise ValueError(f"{attribute.name} must be >= 1 (got {value})")


@attrs.frozen
class SynergyGroup:
    """One synergy group: a model ForceSet group and how many synergies describe it.

    ``muscles`` are the group's NCP muscles in ForceSet-group order (force-applying members
    that cross the tracked coordinates).
    """

    name: str
    muscles: tuple[str, ...] = attrs.field(converter=tuple)
    n_synergies: int = attrs.field(converter=int, validator=_positive_int)

    def __attrs_post_init__(self) -> None:
        if not self.muscles:
            raise ValueError(f"synergy group '{self.name}' has no muscles")
        if self.n_synergies > len(self.muscles):
            raise ValueError(
                f"synergy group '{self.name}' asks for {self.n_synergies} synergies but has only "
                f"{len(self.muscles)} muscles"
            )

    @property
    def n_muscles(self) -> int:
        return len(self.muscles)

    @property
    def synergy_names(self) -> tuple[str, ...]:
        """``<group>_<k>``, k = 1..n_synergies."""
        return tuple(f"{self.name}_{k}" for k in range(1, self.n_synergies + 1))

    @property
    def weight_sum(self) -> float:
        """The constant every synergy vector of this group sums to during optimization."""
        return WEIGHT_SUM_PER_MUSCLE * self.n_muscles


@attrs.frozen
class SynergyLayout:
    """How the synergy groups map to one weight matrix and one command matrix per trial.

    ``n_nodes``: command spline nodes per synergy and trial. ``shared_from``: for each group,
    ``None`` or ``(source_group_index, muscle_map)``; a shared group reuses the source
    group's synergy vectors, its muscle ``i`` taking the source's weight of muscle
    ``muscle_map[i]`` (bilateral symmetry).
    """

    groups: tuple[SynergyGroup, ...] = attrs.field(converter=tuple)
    n_nodes: int = attrs.field(default=DEFAULT_NODE_COUNT, converter=int)
    shared_from: tuple[tuple[int, tuple[int, ...]] | None, ...] = attrs.field(default=None)

    def __attrs_post_init__(self) -> None:
        if not self.groups:
            raise ValueError("at least one synergy group is needed")
        if self.shared_from is None:
            object.__setattr__(self, "shared_from", (None,) * len(self.groups))
        if len(self.shared_from) != len(self.groups):
            raise ValueError("shared_from needs one entry per group")
        names = [m for g in self.groups for m in g.muscles]
        dup = sorted({m for m in names if names.count(m) > 1})
        if dup:
            raise ValueError(f"muscle(s) in more than one synergy group: {', '.join(dup)}")
        for g, share in enumerate(self.shared_from):
            if share is None:
                continue
            src, muscle_map = share
            if self.shared_from[src] is not None:
                raise ValueError(f"group '{self.groups[g].name}' shares vectors with a group that shares too")
            if self.groups[src].n_synergies != self.groups[g].n_synergies:
                raise ValueError(
                    f"groups '{self.groups[src].name}' and '{self.groups[g].name}' must have the same "
                    "number of synergies to share synergy vectors"
                )
            if sorted(muscle_map) != list(range(self.groups[src].n_muscles)) or len(muscle_map) != self.groups[g].n_muscles:
                raise ValueError(f"muscle map of group '{self.groups[g].name}' is not a permutation")

    # ----- sizes and names ----------------------------------------------------------------
    @property
    def muscles(self) -> tuple[str, ...]:
        """All NCP muscles, group by group."""
        return tuple(m for g in self.groups for m in g.muscles)

    @property
    def n_muscles(self) -> int:
        return sum(g.n_muscles for g in self.groups)

    @property
    def n_synergies(self) -> int:
        return sum(g.n_synergies for g in self.groups)

    @property
    def synergy_names(self) -> tuple[str, ...]:
        return tuple(n for g in self.groups for n in g.synergy_names)

    @property
    def free_groups(self) -> tuple[int, ...]:
        """Indices of groups whose synergy vectors are design variables (not shared)."""
        return tuple(i for i, s in enumerate(self.shared_from) if s is None)

    def muscle_slice(self, group: int) -> slice:
        start = sum(g.n_muscles for g in self.groups[:group])
        return slice(start, start + self.groups[group].n_muscles)

    def synergy_slice(self, group: int) -> slice:
        start = sum(g.n_synergies for g in self.groups[:group])
        return slice(start, start + self.groups[group].n_synergies)

    def basis(self, n_points: int) -> np.ndarray:
        """Command interpolation matrix (n_points, n_nodes)."""
        return interpolation_matrix(self.n_nodes, n_points)

    # ----- assembling ---------------------------------------------------------------------
    def group_blocks(self, free_blocks: Sequence[Any]) -> list[Any]:
        """Every group's block (S_g, M_g) from the blocks of the free groups (in ``free_groups`` order)."""
        free = self.free_groups
        if len(free_blocks) != len(free):
            raise ValueError(f"expected {len(free)} weight blocks, got {len(free_blocks)}")
        by_group: dict[int, Any] = dict(zip(free, free_blocks))
        blocks = []
        for g, share in enumerate(self.shared_from):
            if share is None:
                blocks.append(by_group[g])
            else:
                src, muscle_map = share
                blocks.append(_take_columns(by_group[src], muscle_map))
        return blocks

    def weight_matrix(self, free_blocks: Sequence[Any]) -> Any:
        """Block-diagonal ``W`` (S, M) from the free groups' blocks (numpy or CasADi)."""
        blocks = self.group_blocks(free_blocks)
        if all(isinstance(b, np.ndarray) for b in blocks):
            out = np.zeros((self.n_synergies, self.n_muscles))
            for g, block in enumerate(blocks):
                out[self.synergy_slice(g), self.muscle_slice(g)] = block
            return out
        import casadi as cs

        return cs.diagcat(*blocks)

    def split_weights(self, weights: np.ndarray) -> list[np.ndarray]:
        """The free groups' blocks of a full weight matrix (S, M)."""
        weights = np.asarray(weights, dtype=float)
        return [weights[self.synergy_slice(g), self.muscle_slice(g)].copy() for g in self.free_groups]

    def commands(self, nodes: Any, n_points: int) -> Any:
        """Commands (n_points, S) from nodes (n_nodes, S) (numpy or CasADi)."""
        return self.basis(n_points) @ nodes if isinstance(nodes, np.ndarray) else _mx_matmul(self.basis(n_points), nodes)


def activations(weights: Any, commands: Any) -> Any:
    """Muscle activations (P, M) = commands (P, S) @ weights (S, M) (numpy or CasADi)."""
    if isinstance(weights, np.ndarray) and isinstance(commands, np.ndarray):
        return commands @ weights
    import casadi as cs

    return cs.mtimes(commands, weights)


def normalize_by_max_weight(
    weights: np.ndarray, commands: Sequence[np.ndarray]
) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
    """Scale each synergy vector so its largest weight is one (as the original does after the solve).

    ``weights`` (S, M); ``commands`` one (P, S) array per trial. Row ``s`` is divided by
    its maximum and column ``s`` of every command array multiplied by it, so activations
    are unchanged. A vector whose weights are all <= 0 is left as it is.
    Returns ``(weights, commands, factors)`` with ``factors`` (S,) the maxima used.
    """
    weights = np.asarray(weights, dtype=float)
    factors = weights.max(axis=1)
    factors = np.where(factors > 0, factors, 1.0)
    new_weights = weights / factors[:, None]
    new_commands = [np.asarray(c, dtype=float) * factors[None, :] for c in commands]
    return new_weights, new_commands, factors


def _take_columns(block: Any, columns: Sequence[int]) -> Any:
    if isinstance(block, np.ndarray):
        return block[:, list(columns)]
    import casadi as cs

    return cs.horzcat(*[block[:, int(c)] for c in columns])


def _mx_matmul(matrix: np.ndarray, expr: Any) -> Any:
    import casadi as cs

    return cs.mtimes(cs.DM(matrix), expr)

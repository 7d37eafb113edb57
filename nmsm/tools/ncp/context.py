"""What NCP hands to its cost and constraint terms.

:class:`NcpContext` holds the modeled quantities of one NCP evaluation: the synergy
weight blocks and every trial's muscle activations, either as CasADi expressions of the
design variables (while building the problem) or as numpy arrays (when scoring a given
solution, e.g. the MATLAB original's). Terms ask it for raw quantities; its reduction is
NCP's ``raw / e / sqrt(numel)`` (as the original's NCP): :func:`nmsm.core.reductions.mean_square`.

Array conventions: activations (P, M) per trial in NCP muscle order; moments (P, J).
Stacked quantities are column-major vectors over trials in order.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from nmsm.core import reductions
from nmsm.tools.ncp.forces import MomentGains, moment_gains
from nmsm.tools.mtp.muscles import MuscleGroup
from nmsm.tools.ncp.inputs import NcpInputs


def _is_numeric(value: Any) -> bool:
    return isinstance(value, np.ndarray)


def _vec(value: Any) -> Any:
    if _is_numeric(value):
        return np.ravel(value, order="F")
    import casadi as cs

    return cs.vec(value)


def _stack(parts: Sequence[Any]) -> Any:
    if all(_is_numeric(p) for p in parts):
        return np.concatenate(parts) if parts else np.zeros(0)
    import casadi as cs

    return cs.vertcat(*parts)


def _columns(value: Any, indices: Sequence[int]) -> Any:
    if _is_numeric(value):
        return value[:, list(indices)]
    return value[:, list(indices)]


def _gain_matrix(gains: MomentGains) -> Any:
    """Sparse DM mapping vec(activations) (P·M) to vec(active moments) (P·J), column-major."""
    import casadi as cs

    p, j, m = gains.active.shape
    pp, jj, mm = np.meshgrid(np.arange(p), np.arange(j), np.arange(m), indexing="ij")
    rows = (pp + p * jj).ravel()
    cols = (pp + p * mm).ravel()
    values = gains.active.ravel()
    keep = values != 0
    return cs.DM.triplet(rows[keep].tolist(), cols[keep].tolist(), values[keep], p * j, p * m)


class NcpContext:
    """Modeled NCP quantities for the terms (see module docstring).

    ``weight_blocks``: every synergy group's block (S_g, M_g), shared groups included;
    ``activations``: one (P, M) array or expression per trial.
    """

    tool = "NCP"

    def __init__(
        self,
        inputs: NcpInputs,
        weight_blocks: Sequence[Any],
        activations: Sequence[Any],
        *,
        gains: Sequence[MomentGains] | None = None,
    ) -> None:
        if len(activations) != len(inputs.trials):
            raise ValueError(f"{len(activations)} activation blocks for {len(inputs.trials)} trials")
        self.inputs = inputs
        self.weight_blocks = list(weight_blocks)
        self.activations = list(activations)
        self.gains = list(gains) if gains is not None else [moment_gains(t, inputs.muscles, inputs.v_max_factor, inputs.curves) for t in inputs.trials]
        self._gain_matrices: list[Any] | None = None

    # ----- reductions ---------------------------------------------------------------------
    def reduce_cost(self, term: Any, normalized: Any) -> Any:
        """NCP: ``z / sqrt(numel(z))`` (squared sum = mean of squares)."""
        return reductions.mean_square(normalized)

    def reduce_constraint(self, term: Any, value: Any) -> tuple[Any, Any, Any]:
        return value, term.min_error, term.max_error

    # ----- modeled quantities -------------------------------------------------------------
    @property
    def numeric(self) -> bool:
        return all(_is_numeric(a) for a in self.activations)

    def modeled_moments(self, trial: int) -> Any:
        """Muscle joint moments (P, J) of trial ``trial``."""
        gains = self.gains[trial]
        a = self.activations[trial]
        if _is_numeric(a):
            return gains.moments(a)
        import casadi as cs

        if self._gain_matrices is None:
            self._gain_matrices = [_gain_matrix(g) for g in self.gains]
        p, j = gains.passive.shape
        active = cs.reshape(cs.mtimes(self._gain_matrices[trial], cs.vec(a)), p, j)
        return active + cs.DM(gains.passive)

    def moment_errors(self) -> Any:
        """``M_mod - M_ID`` of every trial, stacked (Σ P·J,)."""
        return _stack([_vec(self.modeled_moments(t) - tr.moments) for t, tr in enumerate(self.inputs.trials)])

    def activation_tracking_errors(self) -> Any:
        """``a - a_MTP`` for muscles with MTP activations, stacked; ``0`` (one value) without MTP data."""
        if not self.inputs.has_mtp_activations:
            return np.zeros(1)
        idx = self.inputs.mtp_indices
        return _stack(
            [_vec(_columns(a, idx) - tr.mtp_activations) for a, tr in zip(self.activations, self.inputs.trials)]
        )

    def untracked_activations(self) -> Any:
        """Activations of muscles without MTP activations, stacked (empty when all have them)."""
        idx = self.inputs.other_indices
        if not idx:
            return np.zeros(0)
        return _stack([_vec(_columns(a, idx)) for a in self.activations])

    def grouped_deviations(self, groups: Sequence[MuscleGroup]) -> Any:
        """Per group and trial: activations minus the group's mean activation, stacked."""
        parts = []
        for group in groups:
            for a in self.activations:
                block = _columns(a, group.indices)
                if _is_numeric(block):
                    parts.append(_vec(block - block.mean(axis=1, keepdims=True)))
                else:
                    import casadi as cs

                    mean = cs.sum2(block) / len(group.indices)
                    parts.append(_vec(block - cs.repmat(mean, 1, len(group.indices))))
        return _stack(parts) if parts else np.zeros(0)

    def symmetry_difference(self) -> Any:
        """Synergy vectors of group 1 minus the mirrored vectors of group 2 (exactly two groups)."""
        layout = self.inputs.layout
        if len(layout.groups) != 2:
            raise ValueError(f"bilateral symmetry needs exactly two synergy groups, got {len(layout.groups)}")
        from nmsm.tools.ncp.symmetry import mirror_muscle_map

        first, second = layout.groups
        muscle_map = mirror_muscle_map(second.muscles, first.muscles)
        if first.n_synergies != second.n_synergies:
            raise ValueError("bilateral symmetry needs the same number of synergies in both groups")
        w1, w2 = self.weight_blocks
        if _is_numeric(w2):
            mirrored = w2[:, list(muscle_map)]
        else:
            import casadi as cs

            mirrored = cs.horzcat(*[w2[:, i] for i in muscle_map])
        return _vec(w1 - mirrored)

    def weight_row_sums(self, group: int) -> Any:
        """Sum of each synergy vector of group ``group`` (S_g,)."""
        block = self.weight_blocks[group]
        if _is_numeric(block):
            return block.sum(axis=1)
        import casadi as cs

        return cs.sum2(block)

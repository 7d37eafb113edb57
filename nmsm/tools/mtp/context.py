"""What MTP hands to its cost terms: modeled quantities (CasADi MX) and fixed data.

Terms read these attributes; arrays are stacked over trials on axis 0 where noted.
Reduction: each block of normalized values contributes ``sum(z**2) / numel(z)``
(the original's ``calcDeviationCostTerm`` / ``calcTrackingCostTerm``); a term may return
several blocks (a tuple), each averaged separately, or ask for a plain sum
(``reduction = "plain"``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.reductions import mean_square, plain
from nmsm.tools.mtp.model import MuscleDesign, TrialModel
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters


def reduce_blocks(term: Any, normalized: Any) -> Any:
    """Residuals of one or several blocks (tuple/list) by the term's ``reduction``."""
    how = getattr(term, "reduction", "mean_square")
    reducer = plain if how == "plain" else mean_square
    blocks = normalized if isinstance(normalized, (tuple, list)) else (normalized,)
    parts = [reducer(b) for b in blocks if _numel(b) > 0]
    if not parts:
        return cs.MX(0, 1)
    return cs.vertcat(*[cs.MX(p) if not isinstance(p, cs.MX) else p for p in parts])


def _numel(x: Any) -> int:
    return int(x.numel()) if hasattr(x, "numel") else int(np.size(x))


@attrs.define(eq=False)
class MtpContext:
    """Modeled quantities of one MTP task.

    ``models`` / ``synx_models``: per trial :class:`TrialModel` without / with Synergy
    Extrapolation (``synx_models`` is None when SynX is off). ``initial_fiber_length``:
    per trial (n_frames, n_muscles) normalized fiber lengths with unit scale factors,
    computed once before the first task. ``measured`` / ``missing``: muscle indices with /
    without EMG.
    """

    muscles: MuscleParameters
    design: MuscleDesign
    models: list[TrialModel]
    synx_models: list[TrialModel] | None
    inverse_dynamics_moments: list[np.ndarray]
    initial_fiber_length: list[np.ndarray]
    activation_groups: tuple[MuscleGroup, ...]
    fiber_length_groups: tuple[MuscleGroup, ...]
    measured: tuple[int, ...]
    missing: tuple[int, ...]
    padding: int
    min_normalized_fiber_length: float = 0.75
    max_normalized_fiber_length: float = 1.05
    tool: str = "MTP"

    # ----- reductions -------------------------------------------------------------------
    def reduce_cost(self, term: Any, normalized: Any) -> Any:
        return reduce_blocks(term, normalized)

    def reduce_constraint(self, term: Any, value: Any) -> tuple[Any, Any, Any]:
        return value, term.min_error, term.max_error

    # ----- convenience ------------------------------------------------------------------
    @property
    def synx_enabled(self) -> bool:
        return self.synx_models is not None

    @property
    def primary_models(self) -> list[TrialModel]:
        """The models the fiber-length and passive-force terms use (SynX ones when enabled)."""
        return self.synx_models if self.synx_models is not None else self.models

    @property
    def n_muscles(self) -> int:
        return self.muscles.n_muscles

    def stacked(self, attribute: str, *, synx: bool = False, columns: Sequence[int] | None = None) -> cs.MX:
        """An attribute of every trial's model stacked vertically ``(n_trials * n_frames, k)``."""
        models = self.synx_models if synx else self.models
        if models is None:
            raise ValueError("synergy extrapolation is not enabled")
        blocks = [getattr(m, attribute) for m in models]
        if columns is not None:
            cols = list(columns)
            blocks = [cs.horzcat(*[b[:, c] for c in cols]) if cols else cs.MX(b.shape[0], 0) for b in blocks]
        return cs.vertcat(*blocks)

    def moment_errors(self, *, synx: bool = False) -> cs.MX:
        """Modeled minus inverse-dynamics moments, all trials stacked (N m)."""
        models = self.synx_models if synx else self.models
        if models is None:
            raise ValueError("synergy extrapolation is not enabled")
        return cs.vertcat(*[m.moments - cs.DM(r) for m, r in zip(models, self.inverse_dynamics_moments)])

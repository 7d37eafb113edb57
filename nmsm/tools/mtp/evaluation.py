"""Numeric modeled values of MTP at given parameters (for outputs, reports and tests).

Arrays are stacked ``(n_trials, n_frames, k)``: excitations over the EMG frames,
everything else over the ID frames; moments ``(n_trials, n_frames, n_coordinates)``.
"""

from __future__ import annotations

from collections.abc import Sequence

import attrs
import casadi as cs
import numpy as np

from nmsm.errors import InputError, SolverError
from nmsm.model import hill
from nmsm.tools.mtp.model import MuscleDesign, TrialModel
from nmsm.tools.mtp.problem import MtpData, MtpState, modeled_trials

_FIELDS = (
    "excitations",
    "excitations_undelayed",
    "neural_activations",
    "activations",
    "normalized_fiber_length",
    "normalized_fiber_velocity",
    "tendon_force",
    "passive_force",
    "moments",
)


@attrs.frozen(eq=False)
class ModeledValues:
    """Modeled quantities of all trials (numpy), see the module docstring for shapes."""

    excitations: np.ndarray
    excitations_undelayed: np.ndarray
    neural_activations: np.ndarray
    activations: np.ndarray
    normalized_fiber_length: np.ndarray
    normalized_fiber_velocity: np.ndarray
    tendon_force: np.ndarray
    passive_force: np.ndarray
    moments: np.ndarray

    @property
    def active_force(self) -> np.ndarray:
        return self.tendon_force - self.passive_force


def _numeric(models: Sequence[TrialModel]) -> ModeledValues:
    outs = [getattr(m, f) for m in models for f in _FIELDS]
    values = cs.Function("modeled_values", [], outs).call([])
    arrays = [np.array(v.full()) for v in values]
    k = len(_FIELDS)
    per_field = {f: np.stack([arrays[t * k + i] for t in range(len(models))]) for i, f in enumerate(_FIELDS)}
    for name, arr in per_field.items():
        if not np.all(np.isfinite(arr)):
            raise SolverError(f"modeled {name} is not finite: the parameters are outside the model's range")
    return ModeledValues(**per_field)


def numeric_design(design: MuscleDesign) -> MuscleDesign:
    return MuscleDesign(**{f.name: np.asarray(getattr(design, f.name), dtype=float) for f in attrs.fields(MuscleDesign)})


def evaluate(data: MtpData, state: MtpState) -> tuple[ModeledValues, ModeledValues | None]:
    """Modeled values without and (if SynX is on) with synergy extrapolation."""
    design = numeric_design(state.design)
    weights = cs.DM(np.asarray(state.synergy_weights, dtype=float))
    plain, synx = modeled_trials(data, design, weights)
    return _numeric(plain), (_numeric(synx) if synx is not None else None)


def initial_fiber_lengths(data: MtpData) -> list[np.ndarray]:
    """Normalized fiber lengths (n_frames, n_muscles) per trial with unit scale factors."""
    mus = data.muscles
    return [
        hill.normalized_fiber_length(t.muscle_tendon_length, mus.optimal_fiber_length, mus.tendon_slack_length, mus.pennation_angle)
        for t in data.trials
    ]


def check_fiber_lengths(data: MtpData, *, stage: str, source: str | None = None) -> None:
    """Refuse muscles whose fibers have no positive length at the start of a stage.

    ``L_MT - l_ts <= 0`` (tendon slack length at or above the muscle-tendon length, e.g. a
    bad ``.osimx`` or an MTLI result) gives normalized fiber lengths <= 0 where the Hill
    curves are meaningless and the optimization cannot recover within the scale-factor
    bounds: an :class:`InputError` naming muscle, trial and lengths instead.
    """
    mus = data.muscles
    for trial, lengths in zip(data.trials, initial_fiber_lengths(data)):
        bad = np.flatnonzero(~np.all(np.isfinite(lengths) & (lengths > 0), axis=0))
        if bad.size:
            i = int(bad[0])
            raise InputError(
                f"{stage}: muscle '{mus.names[i]}' has tendon slack length {mus.tendon_slack_length[i]:.4g} m but "
                f"muscle-tendon length down to {trial.muscle_tendon_length[:, i].min():.4g} m in trial "
                f"'{trial.name}' (normalized fiber length {lengths[:, i].min():.3g})"
                + (f"; also {', '.join(mus.names[j] for j in bad[1:])}" if bad.size > 1 else ""),
                file=source,
                element="<tendon_slack_length>",
                expected="0 < tendon slack length < the muscle-tendon length in every frame",
            )

"""Muscle parameters and muscle groups used by MTP / MTLI (from the model and an .osimx).

``MuscleParameters`` holds one value per muscle (SI units, radians) in the tool's muscle
order; ``GroupIndex`` maps ForceSet group names to positions in that order.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence

import attrs
import numpy as np

from nmsm.errors import InputError


def _array(values: Sequence[float] | np.ndarray) -> np.ndarray:
    return np.asarray(values, dtype=float).reshape(-1)


@attrs.frozen(eq=False)
class MuscleParameters:
    """Hill-model parameters, shape (n_muscles,) each.

    ``max_isometric_force`` N, ``optimal_fiber_length`` m, ``tendon_slack_length`` m,
    ``pennation_angle`` rad (at optimal fiber length).
    """

    names: tuple[str, ...] = attrs.field(converter=tuple)
    max_isometric_force: np.ndarray = attrs.field(converter=_array)
    optimal_fiber_length: np.ndarray = attrs.field(converter=_array)
    tendon_slack_length: np.ndarray = attrs.field(converter=_array)
    pennation_angle: np.ndarray = attrs.field(converter=_array)

    def __attrs_post_init__(self) -> None:
        n = len(self.names)
        for field in ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length", "pennation_angle"):
            value = getattr(self, field)
            if value.shape != (n,):
                raise ValueError(f"{field} has shape {value.shape}, expected ({n},)")
        checks = (
            ("max_isometric_force", self.max_isometric_force > 0, "> 0 N"),
            ("optimal_fiber_length", self.optimal_fiber_length > 0, "> 0 m"),
            ("tendon_slack_length", self.tendon_slack_length > 0, "> 0 m"),
            ("pennation_angle", (self.pennation_angle >= 0) & (self.pennation_angle < np.pi / 2), "in [0, pi/2) rad"),
        )
        for field, ok, expected in checks:
            bad = [self.names[i] for i in np.flatnonzero(~(ok & np.isfinite(getattr(self, field))))]
            if bad:
                raise InputError(
                    f"muscle parameter <{field}> invalid for {', '.join(bad)}",
                    element=f"<{field}>",
                    expected=expected,
                )

    @property
    def n_muscles(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def with_lengths(self, optimal_fiber_length: np.ndarray, tendon_slack_length: np.ndarray) -> MuscleParameters:
        return attrs.evolve(self, optimal_fiber_length=optimal_fiber_length, tendon_slack_length=tendon_slack_length)


@attrs.frozen
class MuscleGroup:
    """A named group and the positions of its members in the tool's muscle order."""

    name: str
    indices: tuple[int, ...]


def resolve_groups(
    group_names: Sequence[str],
    model_groups: Mapping[str, Sequence[str]],
    muscle_names: Sequence[str],
    *,
    setting: str,
    model_file: str | None = None,
    settings_file: str | None = None,
    drop_empty: bool = True,
) -> tuple[MuscleGroup, ...]:
    """Groups named in a setting, as indices into ``muscle_names``.

    Unknown group names are an :class:`InputError` naming the settings file (when given),
    the setting, the model and the model's groups. Members outside ``muscle_names`` are ignored (a warning says so);
    a group left empty is dropped (with a warning) unless ``drop_empty`` is False.
    """
    out: list[MuscleGroup] = []
    position = {name: i for i, name in enumerate(muscle_names)}
    for group in group_names:
        if group not in model_groups:
            model = f" {model_file}" if model_file else ""
            raise InputError(
                f"muscle group '{group}' is not a ForceSet group of the model{model}",
                file=settings_file or model_file,
                element=f"<{setting}>",
                expected="one of the model's groups: " + (", ".join(sorted(model_groups)) or "(none)"),
            )
        members = list(model_groups[group])
        inside = [position[m] for m in members if m in position]
        outside = [m for m in members if m not in position]
        if outside:
            warnings.warn(
                f"<{setting}> group '{group}': member(s) {', '.join(outside)} do not cross the tracked "
                "coordinates and are ignored",
                stacklevel=2,
            )
        if not inside and drop_empty:
            warnings.warn(f"<{setting}> group '{group}' has no muscle crossing the tracked coordinates; ignored", stacklevel=2)
            continue
        out.append(MuscleGroup(group, tuple(inside)))
    return tuple(out)


def channel_map(
    muscle_names: Sequence[str],
    collected: Sequence[MuscleGroup],
    missing: Sequence[MuscleGroup],
) -> np.ndarray:
    """Channel index of each muscle (collected channel order), ``-1`` for muscles without EMG.

    Every muscle needs a collected channel or a missing-channel group (SynX); a muscle in
    two collected channels or in none is an :class:`InputError`.
    """
    channel = np.full(len(muscle_names), -1, dtype=int)
    for k, group in enumerate(collected):
        for i in group.indices:
            if channel[i] >= 0:
                raise InputError(
                    f"muscle '{muscle_names[i]}' is in two EMG channel groups: "
                    f"'{collected[channel[i]].name}' and '{group.name}'",
                    element="<collected_emg_channel_muscle_groups>",
                    expected="each muscle in at most one collected EMG channel group",
                )
            channel[i] = k
    in_missing = {i for g in missing for i in g.indices}
    orphans = [muscle_names[i] for i in range(len(muscle_names)) if channel[i] < 0 and i not in in_missing]
    if orphans:
        raise InputError(
            f"muscle(s) {', '.join(orphans)} cross the tracked coordinates but have no EMG channel",
            element="<collected_emg_channel_muscle_groups>",
            expected="every muscle crossing <coordinate_list> in a collected EMG channel group or in "
            "<missing_emg_channel_muscle_groups> (with Synergy Extrapolation enabled)",
        )
    both = [muscle_names[i] for i in in_missing if channel[i] >= 0]
    if both:
        raise InputError(
            f"muscle(s) {', '.join(both)} are both in a collected EMG channel and a missing EMG channel group",
            element="<missing_emg_channel_muscle_groups>",
            expected="a muscle either measured or extrapolated",
        )
    return channel

"""Which muscles NCP models: those crossing the tracked coordinates, grouped into synergy groups.

* A muscle crosses a coordinate list when it applies force and one of its path points
  sits on the child body of a joint owning a listed coordinate (the
  original's ``getMusclesFromCoordinates``).
* Every crossing muscle must belong to a synergy group; a synergy group's members that do
  not cross the coordinates are not modeled, and members that do not apply force are
  dropped with a warning (docs/ncp.md).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path

from nmsm.errors import InputError
from nmsm.io.names import close_matches
from nmsm.model.components import Model
from nmsm.tools.ncp.synergies import SynergyGroup


def muscles_crossing(model: Model, coordinates: Sequence[str], *, settings_file: str | Path | None = None) -> list[str]:
    """Force-applying muscles (model order) with a path point on the child body of a joint owning a coordinate.

    A name that is no coordinate of the model is an :class:`InputError` (the original's
    ``getMusclesFromCoordinates`` fails on it too): it crosses nothing, so a misspelled
    coordinate would silently leave its muscles out of the synergy groups.
    """
    known = set(model.coordinate_names)
    for name in coordinates:
        if name not in known:
            close = close_matches(name, model.coordinate_names)
            raise InputError(
                f"'{name}' is not a coordinate of model {model.file}"
                + (f"; close matches: {', '.join(close)}" if close else ""),
                file=settings_file,
                element="<coordinate_list>",
                expected="coordinate names of the model",
            )
    wanted = set(coordinates)
    bodies = {j.child_body for j in model.joints if wanted.intersection(j.coordinates)}
    out = []
    for muscle in model.muscles:
        if not muscle.applies_force:
            continue
        if any(point.body in bodies for point in muscle.geometry.points):
            out.append(muscle.name)
    return out


def synergy_groups(
    model: Model,
    requested: Sequence[tuple[str, int]],
    crossing: Sequence[str],
    *,
    settings_file: str | Path | None = None,
) -> list[SynergyGroup]:
    """Synergy groups from ``(ForceSet group name, number of synergies)`` pairs.

    Raises :class:`InputError` (naming the settings file and element) for a group missing
    from the model, a member that is not a muscle of the model, a group without crossing
    muscles, more synergies than muscles, a muscle in two groups, or a crossing muscle in
    no group.
    """
    by_name = {m.name: m for m in model.muscles}
    crossing_set = set(crossing)
    groups: list[SynergyGroup] = []
    owner: dict[str, str] = {}
    for name, count in requested:
        if name not in model.groups:
            close = close_matches(name, model.groups)
            raise InputError(
                f"synergy group '{name}' is not a ForceSet group of model {model.file}"
                + (f"; close matches: {', '.join(close)}" if close else ""),
                file=settings_file,
                element="<RCNLSynergy>/<muscle_group_name>",
                expected="one of the model's groups: " + (", ".join(sorted(model.groups)) or "(none)"),
            )
        members = model.group_members(name)
        unknown = [m for m in members if m not in by_name]
        if unknown:
            raise InputError(
                f"synergy group '{name}' lists {', '.join(unknown)}, which is not a muscle of model {model.file}",
                file=settings_file,
                element="<RCNLSynergy>/<muscle_group_name>",
                expected="a ForceSet group whose members are muscles",
            )
        idle = [m for m in members if not by_name[m].applies_force]
        if idle:
            warnings.warn(
                f"synergy group '{name}': {', '.join(idle)} do(es) not apply force and is left out", stacklevel=2
            )
        muscles = [m for m in members if m in crossing_set]
        if not muscles:
            raise InputError(
                f"synergy group '{name}' has no force-applying muscle crossing the coordinates of <coordinate_list>",
                file=settings_file,
                element="<RCNLSynergy>/<muscle_group_name>",
                expected="a group of muscles crossing the tracked coordinates",
            )
        if count > len(muscles):
            raise InputError(
                f"synergy group '{name}' asks for {count} synergies but has {len(muscles)} muscle(s) "
                f"crossing the tracked coordinates",
                file=settings_file,
                element="<RCNLSynergy>/<num_synergies>",
                expected=f"at most {len(muscles)} synergies",
            )
        twice = [m for m in muscles if m in owner]
        if twice:
            raise InputError(
                f"muscle(s) {', '.join(twice)} are in synergy groups '{owner[twice[0]]}' and '{name}'",
                file=settings_file,
                element="<RCNLSynergySet>",
                expected="each muscle in one synergy group",
            )
        owner.update({m: name for m in muscles})
        groups.append(SynergyGroup(name, muscles, count))
    orphans = [m for m in crossing if m not in owner]
    if orphans:
        raise InputError(
            f"muscle(s) {', '.join(orphans)} cross the coordinates of <coordinate_list> but are in no synergy group",
            file=settings_file,
            element="<RCNLSynergySet>",
            expected="every muscle crossing the tracked coordinates in a synergy group",
        )
    return groups

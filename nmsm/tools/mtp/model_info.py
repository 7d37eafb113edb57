"""What MTP / MTLI need from the model: the muscles of the tracked coordinates and their parameters.

Muscle set (``getMusclesFromCoordinates``): force-applying muscles with a path point on
the child body of a joint that owns a listed coordinate, in the model's muscle order.
Parameters come from the model, overridden by an ``.osimx`` ``RCNLMuscle`` entry of the
same name when it has the value; an entry naming no muscle of the model is an error.
"""

from __future__ import annotations

from collections.abc import Sequence

from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel, check_muscles_in_model
from nmsm.model.components import Model
from nmsm.tools.mtp.muscles import MuscleParameters


def muscles_crossing(model: Model, coordinates: Sequence[str]) -> list[str]:
    """Force-applying muscles with a path point on a child body of the joints of ``coordinates``."""
    known = set(model.coordinate_names)
    unknown = [c for c in coordinates if c not in known]
    if unknown:
        raise InputError(
            f"coordinate(s) {', '.join(unknown)} not in model '{model.name}'",
            file=model.file,
            element="<coordinate_list>",
            expected="coordinate names of the model",
        )
    bodies = {j.child_body for j in model.joints if set(j.coordinates) & set(coordinates)}
    out = []
    for muscle in model.muscles:
        if not muscle.applies_force:
            continue
        if any(p.body in bodies for p in muscle.geometry.points):
            out.append(muscle.name)
    if not out:
        raise InputError(
            f"no force-applying muscle crosses {', '.join(coordinates)}",
            file=model.file,
            element="<coordinate_list>",
            expected="coordinates spanned by muscles of the model",
        )
    return out


def muscle_parameters(model: Model, names: Sequence[str], osimx: OsimxModel | None = None) -> MuscleParameters:
    """Parameters (N, m, rad) of ``names`` from the model, with ``.osimx`` values taking precedence.

    Every ``RCNLMuscle`` of the ``.osimx`` must be a muscle of the model (``InputError``
    otherwise); it may hold muscles the tool does not use (``names`` is a subset).
    """
    if osimx is not None:
        check_muscles_in_model(osimx, model.muscle_names, model_file=model.file)
    f0, lo, lts, alpha = [], [], [], []
    for name in names:
        muscle = model.muscle(name)
        entry = osimx.muscles.get(name) if osimx is not None else None
        f0.append(entry.max_isometric_force if entry is not None and entry.max_isometric_force is not None
                  else muscle.max_isometric_force)
        lo.append(entry.optimal_fiber_length if entry is not None and entry.optimal_fiber_length is not None
                  else muscle.optimal_fiber_length)
        lts.append(entry.tendon_slack_length if entry is not None and entry.tendon_slack_length is not None
                   else muscle.tendon_slack_length)
        alpha.append(muscle.pennation_angle_at_optimal)
    return MuscleParameters(names, f0, lo, lts, alpha)

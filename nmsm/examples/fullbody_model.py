"""The full-body gait model: the GCP tutorial's skeleton with all 86 leg muscles.

:func:`write_fullbody_model` writes ``bodyModel.osim`` (the skeleton the tutorial's IK, ID
and GRF were made with; its 9 muscles carry strengths raised for a 9-muscle leg) with

* its muscles replaced by the 86 Millard muscles of the JMP tutorial's
  ``UF_Subject_3_Scaled.osim`` (the same subject: the muscles' path points are identical in
  both files, the strengths are the scaled model's own),
* the ForceSet groups of that model (``right_leg``, ``left_leg``: 43 muscles each, and the
  functional groups), its CoordinateActuators kept,
* left-foot markers ``L_Toe_Medial`` and ``L_Toe_Lateral`` (GCP's foot outline; the skeleton
  has them on the right foot only): the right foot's markers mirrored across the calcaneus
  sagittal plane (``z -> -z`` in ``calcn_l``).

Only XML is edited (no OpenSim); the output is a plain ``.osim``.
"""

from __future__ import annotations

import copy
import os
import xml.etree.ElementTree as ET
from pathlib import Path

from nmsm.errors import InputError

#: markers added to the left foot, mirrored from these right-foot markers
MIRRORED_MARKERS = {"L_Toe_Medial": "R_Toe_Medial", "L_Toe_Lateral": "R_Toe_Lateral"}


def _muscles(force_set: ET.Element) -> list[ET.Element]:
    objects = force_set.find("objects")
    return [] if objects is None else [o for o in objects if o.tag.endswith("Muscle")]


def _force_set(root: ET.Element, path: Path) -> ET.Element:
    found = root.find("./Model/ForceSet")
    if found is None:
        raise InputError("no <ForceSet>", file=path, element="<Model>", expected="an OpenSim 4 model")
    return found


def _mirrored_marker(markers: ET.Element, name: str, source: str, path: Path) -> ET.Element:
    template = next((m for m in markers if m.get("name") == source), None)
    if template is None:
        raise InputError(f"marker '{source}' not found", file=path, element="<MarkerSet>",
                         expected=f"{source} (mirrored to {name})")
    marker = copy.deepcopy(template)
    marker.set("name", name)
    marker.find("socket_parent_frame").text = "/bodyset/calcn_l"  # type: ignore[union-attr]
    x, y, z = (float(v) for v in marker.findtext("location", "").split())
    marker.find("location").text = f"{x!r} {y!r} {-z!r}"  # type: ignore[union-attr]
    return marker


def write_fullbody_model(body_model: str | os.PathLike[str], muscle_model: str | os.PathLike[str],
                         output: str | os.PathLike[str]) -> Path:
    """Write the 86-muscle full-body model (module docstring) to ``output``."""
    body_model, muscle_model, output = Path(body_model), Path(muscle_model), Path(output)
    body = ET.parse(body_model)
    donor = ET.parse(muscle_model).getroot()
    body_forces = _force_set(body.getroot(), body_model)
    donor_forces = _force_set(donor, muscle_model)
    objects = body_forces.find("objects")
    assert objects is not None
    for muscle in _muscles(body_forces):
        objects.remove(muscle)
    new_muscles = _muscles(donor_forces)
    if len(new_muscles) != 86:
        raise InputError(f"{len(new_muscles)} muscles", file=muscle_model, element="<ForceSet>",
                         expected="the 86 muscles of the RCNL full-body model")
    for k, muscle in enumerate(new_muscles):
        objects.insert(k, copy.deepcopy(muscle))
    groups = body_forces.find("groups")
    if groups is not None:
        body_forces.remove(groups)
    donor_groups = donor_forces.find("groups")
    if donor_groups is not None:
        body_forces.append(copy.deepcopy(donor_groups))
    markers = body.getroot().find("./Model/MarkerSet/objects")
    if markers is None:
        raise InputError("no markers", file=body_model, element="<MarkerSet>", expected="the foot markers")
    have = {m.get("name") for m in markers}
    for name, source in MIRRORED_MARKERS.items():
        if name not in have:
            markers.append(_mirrored_marker(markers, name, source, body_model))
    model = body.getroot().find("Model")
    assert model is not None
    model.set("name", "fullbody_86_muscles")
    output.parent.mkdir(parents=True, exist_ok=True)
    partial = output.with_name(output.name + ".partial")
    body.write(partial, encoding="UTF-8", xml_declaration=True)
    os.replace(partial, output)
    return output

"""Foot contact of the full-body gait case: GCP of each foot, merged into one ``.osimx``.

:func:`gcp_settings_xml` rewrites the GCP tutorial's right-foot settings (``GCPSettingsV4``:
three tasks, 1.4 m/s treadmill) for the case's model and one foot: the right foot keeps the
tutorial's surface (plate 2), the left foot gets plate 1's columns, ``calcn_l`` and the
left markers (``L_Toe_Medial``/``L_Toe_Lateral`` are the mirrored markers of
:mod:`nmsm.examples.fullbody_model`). Each foot runs as its own GCP (one surface per
settings file); :func:`merge_contact` puts both feet's surfaces into the synergy ``.osimx``.

Without GCP runs (``quick`` cases, for tests): :func:`mirrored_surface` makes a left foot
from a right foot's surface (the GCP tutorial's result): springs on ``calcn_l``/``toes_l``
at the mirrored locations (``z -> -z``), plate 1's columns, the left markers, the same
spring constants and contact properties.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import attrs

from nmsm.errors import InputError
from nmsm.examples.subject_settings import _relative
from nmsm.io.osimx import OsimxContactSurface, OsimxModel, read_osimx, write_osimx

#: per foot: surface name, force plate number, hindfoot body, marker prefix
FEET = {"r": ("Right foot", 2, "calcn_r", "R"), "l": ("Left foot", 1, "calcn_l", "L")}


def _set(parent: ET.Element, tag: str, text: str, where: Path) -> None:
    element = parent.find(tag)
    if element is None:
        raise InputError(f"no <{tag}>", file=where, expected="the GCP tutorial's settings layout")
    element.text = text


def gcp_settings_xml(tutorial_settings: Path, folder: Path, *, side: str, model: Path, preprocessed: Path,
                     results: Path) -> str:
    """The tutorial's GCP settings for foot ``side`` ('r' or 'l'), paths relative to ``folder``."""
    tree = ET.parse(tutorial_settings)
    tool = tree.getroot().find("GroundContactPersonalizationTool")
    if tool is None:
        raise InputError("no <GroundContactPersonalizationTool>", file=tutorial_settings)
    _set(tool, "results_directory", _relative(results, folder), tutorial_settings)
    _set(tool, "input_directory", str(preprocessed.resolve()), tutorial_settings)
    _set(tool, "input_model_file", _relative(model, folder), tutorial_settings)
    surfaces = tool.findall("GCPContactSurfaceSet/GCPContactSurface")
    if len(surfaces) != 1:
        raise InputError(f"{len(surfaces)} contact surfaces", file=tutorial_settings,
                         element="<GCPContactSurfaceSet>", expected="the tutorial's one (right) foot")
    surface = surfaces[0]
    name, plate, hindfoot, prefix = FEET[side]
    surface.set("name", name)
    _set(surface, "is_left_foot", "true" if side == "l" else "false", tutorial_settings)
    _set(surface, "force_columns", " ".join(f"ground_force_{plate}_v{a}" for a in "xyz"), tutorial_settings)
    _set(surface, "moment_columns", " ".join(f"ground_moment_{plate}_m{a}" for a in "xyz"), tutorial_settings)
    _set(surface, "electrical_center_columns", " ".join(f"ground_force_{plate}_p{a}" for a in "xyz"),
         tutorial_settings)
    _set(surface, "hindfoot_body", hindfoot, tutorial_settings)
    for tag, marker in (("toe_marker", "Toe"), ("medial_marker", "Toe_Medial"), ("lateral_marker", "Toe_Lateral"),
                        ("heel_marker", "Heel"), ("midfoot_superior_marker", "Midfoot_Superior")):
        _set(surface, tag, f"{prefix}_{marker}", tutorial_settings)
    ET.indent(tree)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            f"<!-- Full-body gait case: GCP of the {name.lower()}, from the GCP tutorial's "
            f"{tutorial_settings.name}. -->\n" + ET.tostring(tree.getroot(), encoding="unicode") + "\n")


def merge_contact(osimx: str | os.PathLike[str], feet: Sequence[str | os.PathLike[str]],
                  output: str | os.PathLike[str]) -> Path:
    """``osimx`` (muscles, synergies) with the contact surfaces of the ``feet`` GCP ``.osimx``
    files, written to ``output``."""
    base: OsimxModel = read_osimx(osimx)
    surfaces = tuple(s for f in feet for s in read_osimx(f).contact_surfaces)
    return write_osimx(output, attrs.evolve(base, contact_surfaces=base.contact_surfaces + surfaces))


def _left(name: str) -> str:
    return name[:-2] + "_l" if name.endswith("_r") else name


def mirrored_surface(surface: OsimxContactSurface) -> OsimxContactSurface:
    """The left-foot mirror image of a right foot's contact surface (module docstring)."""
    if surface.is_left_foot:
        raise InputError("the surface to mirror is a left foot", element="<is_left_foot>", expected="a right foot")
    _, plate, hindfoot, prefix = FEET["l"]
    springs = tuple(attrs.evolve(k, parent_body=_left(k.parent_body),
                                 location=(k.location[0], k.location[1], -k.location[2])) for k in surface.springs)
    marker = lambda name: prefix + name[1:] if name.startswith("R_") else name  # noqa: E731
    return attrs.evolve(
        surface, is_left_foot=True, hindfoot_body=hindfoot, springs=springs,
        force_columns=tuple(f"ground_force_{plate}_v{a}" for a in "xyz"),
        moment_columns=tuple(f"ground_moment_{plate}_m{a}" for a in "xyz"),
        electrical_center_columns=tuple(f"ground_force_{plate}_p{a}" for a in "xyz"),
        toe_marker=marker(surface.toe_marker), medial_marker=marker(surface.medial_marker),
        lateral_marker=marker(surface.lateral_marker), heel_marker=marker(surface.heel_marker),
        midfoot_superior_marker=marker(surface.midfoot_superior_marker))


def write_mirrored_feet(right_osimx: str | os.PathLike[str], folder: str | os.PathLike[str]) -> tuple[Path, Path]:
    """``folder/right_gcp.osimx`` (the right foot's surfaces of ``right_osimx``) and
    ``folder/left_gcp.osimx`` (their mirror images)."""
    source = read_osimx(right_osimx)
    right = tuple(s for s in source.contact_surfaces if not s.is_left_foot)
    if not right:
        raise InputError("no right-foot contact surface", file=right_osimx, element="<RCNLContactSurfaceSet>",
                         expected="a GCP result of the right foot")
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    base = attrs.evolve(source, muscles={}, synergies=())
    paths = (folder / "right_gcp.osimx", folder / "left_gcp.osimx")
    write_osimx(paths[0], attrs.evolve(base, contact_surfaces=right))
    write_osimx(paths[1], attrs.evolve(base, contact_surfaces=tuple(mirrored_surface(s) for s in right)))
    return paths

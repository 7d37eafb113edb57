"""Two-foot GCP settings built from the subject-3 GCP tutorial (``gcp/uf_subject3_tutorial``).

The tutorial personalizes the right foot only; its trial ``gait_1`` has two force plates:
plate 2 (``ground_force_2_*``, electrical center z = 0.75 m) carries the right foot and
plate 1 (``ground_force_1_*``, z = 0.22 m) the left foot, in stance at both ends of the
0.5-1.6 s window. The tutorial's ``bodyModel.osim`` has the left foot's heel, toe and
midfoot-superior markers but not its medial and lateral toe markers;
:func:`write_two_feet_tutorial` writes into a folder:

* ``bodyModel.osim``: the tutorial's model with ``L_Toe_Medial`` and ``L_Toe_Lateral``
  added on ``calcn_l`` at the mirror images (z negated) of ``R_Toe_Medial`` and
  ``R_Toe_Lateral`` on ``calcn_r`` (how the lab's full-body models place them, e.g.
  ``models/RCNL2024.osim``);
* ``GCPSettings.xml``: the tutorial's ``GCPSettingsV<version>.xml`` with one
  ``<GCPContactSurface>`` per requested foot (:data:`SURFACES`), the motion and GRF files
  read from the tutorial's ``preprocessed`` folder, results into ``<folder>/results``.

The tutorial's files are read, never written.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from lxml import etree

from nmsm.io.xml_input import xml_parser

#: foot -> (surface name, is_left_foot, plate number, hindfoot body, marker prefix)
SURFACES = {
    "right": ("Right foot", False, 2, "calcn_r", "R_"),
    "left": ("Left foot", True, 1, "calcn_l", "L_"),
}
#: the left-foot markers the tutorial's model lacks, made from the right foot's by mirroring
MIRRORED_MARKERS = {"L_Toe_Medial": "R_Toe_Medial", "L_Toe_Lateral": "R_Toe_Lateral"}


def _child(parent: etree._Element, tag: str, text: str | None = None) -> etree._Element:
    element = etree.SubElement(parent, tag)
    if text is not None:
        element.text = text
    return element


def model_with_left_toe_markers(model_file: Path, out: Path) -> Path:
    """Copy ``model_file`` to ``out`` with :data:`MIRRORED_MARKERS` added (module docstring)."""
    tree = etree.parse(str(model_file), xml_parser(huge_tree=True, remove_blank_text=True))
    markers = tree.find(".//MarkerSet/objects")
    existing = {m.get("name"): m for m in markers.findall("Marker")}
    for name, source in MIRRORED_MARKERS.items():
        if name in existing:
            continue
        right = existing[source]
        x, y, z = (float(v) for v in right.findtext("location").split())
        marker = _child(markers, "Marker")
        marker.set("name", name)
        parent = right.findtext("socket_parent_frame").replace("calcn_r", "calcn_l")
        _child(marker, "socket_parent_frame", parent)
        _child(marker, "location", f"{x!r} {y!r} {-z!r}")
        _child(marker, "fixed", right.findtext("fixed") or "false")
    tree.write(str(out), pretty_print=True, xml_declaration=True, encoding="UTF-8")
    return out


def contact_surface(foot: str, start_time: float = 0.5, end_time: float = 1.6, belt_speed: float = 1.4
                    ) -> etree._Element:
    """The ``<GCPContactSurface>`` of ``foot`` ("right" or "left") on its plate."""
    name, is_left, plate, body, prefix = SURFACES[foot]
    surface = etree.Element("GCPContactSurface", name=name)
    _child(surface, "is_enabled", "true")
    _child(surface, "is_left_foot", "true" if is_left else "false")
    _child(surface, "start_time", repr(start_time))
    _child(surface, "end_time", repr(end_time))
    _child(surface, "belt_speed", repr(belt_speed))
    _child(surface, "force_columns", " ".join(f"ground_force_{plate}_v{a}" for a in "xyz"))
    _child(surface, "moment_columns", " ".join(f"ground_moment_{plate}_m{a}" for a in "xyz"))
    _child(surface, "electrical_center_columns", " ".join(f"ground_force_{plate}_p{a}" for a in "xyz"))
    _child(surface, "hindfoot_body", body)
    for element, marker in (("toe_marker", "Toe"), ("medial_marker", "Toe_Medial"), ("lateral_marker", "Toe_Lateral"),
                            ("heel_marker", "Heel"), ("midfoot_superior_marker", "Midfoot_Superior")):
        _child(surface, element, prefix + marker)
    return surface


def write_two_feet_tutorial(tutorial: str | Path, folder: str | Path, *, feet: Sequence[str] = ("right", "left"),
                            version: int = 1, max_iterations: int | None = None) -> Path:
    """Write the model copy and the settings of the module docstring into ``folder``
    (created) and return the settings file. ``feet``: the surfaces in file order;
    ``max_iterations``: replaces the tutorial's iteration limit."""
    tutorial, folder = Path(tutorial), Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    model = model_with_left_toe_markers(tutorial / "bodyModel.osim", folder / "bodyModel.osim")
    source = tutorial / "CompletedSettingsFiles" / f"GCPSettingsV{version}.xml"
    tree = etree.parse(str(source), xml_parser(remove_blank_text=True))
    tool = tree.find("GroundContactPersonalizationTool")
    tool.find("results_directory").text = str(folder / "results")
    tool.find("input_directory").text = str(tutorial / "preprocessed")
    tool.find("input_model_file").text = str(model)
    if max_iterations is not None:
        tool.find("max_iterations").text = str(max_iterations)
    surfaces = tool.find("GCPContactSurfaceSet")
    for old in surfaces.findall("GCPContactSurface"):
        surfaces.remove(old)
    for foot in feet:
        surfaces.append(contact_surface(foot))
    out = folder / "GCPSettings.xml"
    tree.write(str(out), pretty_print=True, xml_declaration=False, encoding="UTF-8")
    return out

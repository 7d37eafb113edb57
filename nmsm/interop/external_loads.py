"""Ground reactions as OpenSim reads them: a ``.mot`` data file and an ExternalLoads XML.

A :class:`GroundReaction` is one force applied to one body: force (N), point of application
(m) and torque (N m), all expressed in ground, over time. :func:`write_external_loads`
writes the data file (columns ``<name>_force_vx``, ``_vy``, ``_vz``, ``<name>_force_px``,
..., ``<name>_torque_x``, ...) and the ExternalLoads XML naming them, which OpenSim's
Inverse Dynamics tool (and nmsm's, :mod:`nmsm.model.external_loads`) apply.

:func:`reaction_from_resultant` turns a resultant (force and moment about the ground
origin) into the force-plate form: the centre of pressure on the floor (``y =
floor_height``) and the free torque about the vertical axis; below ``threshold`` N of
vertical force (swing) the force and torque are written as zero and the point as NaN,
as a force plate's software does.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np
from lxml import etree

from nmsm.io.storage import table_from_columns, write_storage

FORCE_SUFFIX, POINT_SUFFIX, TORQUE_SUFFIX = "_force_v", "_force_p", "_torque_"


@attrs.frozen
class GroundReaction:
    """One applied load over ``time`` (T,) s: ``force``, ``point``, ``torque`` (T, 3) in
    ground (N, m, N m; ``point`` NaN where there is no contact), on ``body``; ``name``
    prefixes its data columns."""

    name: str
    body: str
    time: np.ndarray
    force: np.ndarray
    point: np.ndarray
    torque: np.ndarray

    def columns(self) -> dict[str, np.ndarray]:
        out: dict[str, np.ndarray] = {}
        for suffix, values in ((FORCE_SUFFIX, self.force), (POINT_SUFFIX, self.point), (TORQUE_SUFFIX, self.torque)):
            for k, axis in enumerate("xyz"):
                out[f"{self.name}{suffix}{axis}"] = np.asarray(values)[:, k]
        return out


def reaction_from_resultant(name: str, body: str, time: np.ndarray, force: np.ndarray, moment: np.ndarray, *,
                            floor_height: float = 0.0, threshold: float = 5.0) -> GroundReaction:
    """Force-plate form of a resultant ``force`` (T, 3) N and ``moment`` (T, 3) N m about the
    ground origin (module docstring): the point on ``y = floor_height`` where the moment has
    only a vertical component, and that component."""
    force = np.asarray(force, dtype=float)
    moment = np.asarray(moment, dtype=float)
    fy = force[:, 1]
    contact = fy > threshold
    point = np.full_like(force, np.nan)
    torque = np.zeros_like(force)
    h = floor_height
    safe = np.where(contact, fy, 1.0)
    # M = p x F + (0, T, 0) with p = (px, h, pz)
    px = (moment[:, 2] + h * force[:, 0]) / safe
    pz = (h * force[:, 2] - moment[:, 0]) / safe
    point[contact, 0], point[contact, 1], point[contact, 2] = px[contact], h, pz[contact]
    ty = moment[:, 1] - (pz * force[:, 0] - px * force[:, 2])
    torque[contact, 1] = ty[contact]
    out_force = np.where(contact[:, None], force, 0.0)
    return GroundReaction(name, body, np.asarray(time, dtype=float), out_force, point, torque)


def external_loads_xml(reactions: Sequence[GroundReaction], datafile: str, name: str = "external_loads") -> bytes:
    """ExternalLoads XML text for ``reactions`` whose columns are in ``datafile``."""
    root = etree.Element("OpenSimDocument", Version="40000")
    loads = etree.SubElement(root, "ExternalLoads", name=name)
    objects = etree.SubElement(loads, "objects")
    for reaction in reactions:
        force = etree.SubElement(objects, "ExternalForce", name=reaction.name)
        for tag, text in (("applied_to_body", reaction.body), ("force_expressed_in_body", "ground"),
                          ("point_expressed_in_body", "ground"),
                          ("force_identifier", reaction.name + FORCE_SUFFIX),
                          ("point_identifier", reaction.name + POINT_SUFFIX),
                          ("torque_identifier", reaction.name + TORQUE_SUFFIX),
                          ("data_source_name", "Unassigned")):
            etree.SubElement(force, tag).text = text
    etree.SubElement(loads, "groups")
    etree.SubElement(loads, "datafile").text = datafile
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


def write_external_loads(xml_path: str | os.PathLike[str], reactions: Sequence[GroundReaction],
                         data_path: str | os.PathLike[str] | None = None) -> tuple[Path, Path]:
    """Write the data file (default: ``xml_path`` with ``.mot``) and the ExternalLoads XML
    (data file named relative to it); returns ``(xml, data)`` paths."""
    xml_path = Path(xml_path)
    data = Path(data_path) if data_path is not None else xml_path.with_suffix(".mot")
    times = {tuple(np.round(r.time, 12)) for r in reactions}
    if len(times) != 1:
        raise ValueError("all reactions must share one time base")
    columns: dict[str, np.ndarray] = {}
    for reaction in reactions:
        columns.update(reaction.columns())
    write_storage(data, table_from_columns(reactions[0].time, columns, name=data.stem))
    relative = os.path.relpath(data.resolve(), xml_path.resolve().parent)
    xml_path.write_bytes(external_loads_xml(reactions, Path(relative).as_posix()))
    return xml_path, data

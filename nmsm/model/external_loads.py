"""OpenSim ExternalLoads files (``<ExternalLoads>`` with ``<ExternalForce>`` entries) and the
loads they describe at given times.

An ExternalForce applies to ``applied_to_body`` the force whose columns are
``<force_identifier>x|y|z`` (N, in ``force_expressed_in_body``), at the point
``<point_identifier>x|y|z`` (m, in ``point_expressed_in_body``; the body origin when no point
is given), plus the torque ``<torque_identifier>x|y|z`` (N m, in the force's frame). Data
are interpolated in time as OpenSim does: a natural cubic spline through the samples (a
degree-3 GCV spline with zero error variance), piecewise linear for 2-3 samples.
Centre-of-pressure NaNs (swing) are allowed; where the point is NaN the force should be
zero (a warning otherwise) and the point is replaced by zeros.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import attrs
import numpy as np
from lxml import etree
from scipy.interpolate import CubicSpline

from nmsm.errors import InputError
from nmsm.io.storage import Table, read_storage
from nmsm.io.xml_input import refuse_entities, xml_parser


@attrs.frozen
class ExternalForceSpec:
    """One ``<ExternalForce>``: names of the body, frames and data columns."""

    name: str
    body: str
    force_frame: str = "ground"
    point_frame: str = "ground"
    force_identifier: str = ""
    point_identifier: str = ""
    torque_identifier: str = ""


@attrs.frozen
class ExternalLoads:
    """The forces of an ExternalLoads file and its data file (absolute path or None)."""

    forces: tuple[ExternalForceSpec, ...]
    data_file: Path | None
    source: Path | None = None


def read_external_loads(path: str | Path) -> ExternalLoads:
    """Read an OpenSim ExternalLoads XML file (data file resolved relative to it)."""
    path = Path(path)
    try:
        root = etree.parse(str(path), xml_parser()).getroot()
    except (OSError, etree.XMLSyntaxError) as exc:
        raise InputError(f"cannot read external loads ({exc})", file=path, expected="an OpenSim ExternalLoads XML file") from None
    refuse_entities(root, path, "external loads file")
    loads = root if root.tag == "ExternalLoads" else root.find("ExternalLoads")
    if loads is None:
        raise InputError("no <ExternalLoads> element", file=path, expected="an OpenSim ExternalLoads XML file")

    def text(elem: etree._Element, tag: str, default: str = "") -> str:
        child = elem.find(tag)
        return child.text.strip() if child is not None and child.text and child.text.strip() else default

    forces = []
    for elem in loads.iter("ExternalForce"):
        name = elem.get("name", "")
        body = text(elem, "applied_to_body") or text(elem, "socket_applied_to_body")
        if not body:
            raise InputError("ExternalForce without <applied_to_body>", file=path, line=elem.sourceline,
                             element=f"ExternalForce '{name}'", expected="the name of a body")
        force_id = text(elem, "force_identifier")
        if not force_id:
            raise InputError("ExternalForce without <force_identifier>", file=path, line=elem.sourceline,
                             element=f"ExternalForce '{name}'", expected="the prefix of the force columns")
        forces.append(ExternalForceSpec(
            name, body.split("/")[-1], text(elem, "force_expressed_in_body", "ground").split("/")[-1],
            text(elem, "point_expressed_in_body", "ground").split("/")[-1], force_id,
            text(elem, "point_identifier"), text(elem, "torque_identifier")))
    datafile = text(loads, "datafile")
    data_path = None
    if datafile:
        data_path = Path(datafile.replace("\\", "/"))
        if not data_path.is_absolute():
            data_path = path.parent / data_path
    return ExternalLoads(tuple(forces), data_path, path)


def _columns(table: Table, identifier: str, what: str, spec: ExternalForceSpec) -> np.ndarray:
    labels = [identifier + axis for axis in "xyz"]
    missing = [label for label in labels if not table.has(label)]
    if missing:
        raise InputError(f"ExternalForce '{spec.name}' needs {what} columns {', '.join(missing)}",
                         file=table.source, element="column labels", expected=", ".join(labels))
    return table.columns(labels)


def _interpolator(times: np.ndarray, values: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    n = times.size
    if n == 1:
        return lambda t: np.repeat(values[:1], np.size(t), axis=0)
    if n < 4:
        return lambda t: np.column_stack([np.interp(t, times, values[:, i]) for i in range(values.shape[1])])
    spline = CubicSpline(times, values, bc_type="natural", axis=0)
    return lambda t: spline(t)


@attrs.define
class SampledLoad:
    """One external force sampled at given times: ``force``, ``point``, ``torque`` ``(m, 3)``
    in the frames named by ``force_frame`` / ``point_frame`` (torque in the force frame)."""

    spec: ExternalForceSpec
    force: np.ndarray
    point: np.ndarray | None
    torque: np.ndarray


def sample_loads(loads: ExternalLoads, times: np.ndarray, table: Table | None = None) -> list[SampledLoad]:
    """The loads at ``times`` (s) from ``table`` (default: the loads' data file)."""
    if table is None:
        if loads.data_file is None:
            raise InputError("the external loads name no data file", file=loads.source, element="datafile",
                             expected="<datafile> naming the GRF .mot file")
        table = read_storage(loads.data_file, allow_nan=lambda label: label[-2:] in ("px", "py", "pz"))
    times = np.asarray(times, dtype=float)
    if times.size and (times[0] < table.time[0] - 1e-9 or times[-1] > table.time[-1] + 1e-9):
        raise InputError(f"external load data cover {table.time[0]:g}-{table.time[-1]:g} s, the motion "
                         f"{times[0]:g}-{times[-1]:g} s", file=table.source, element="time",
                         expected="load data covering the whole motion")
    out = []
    for spec in loads.forces:
        force = _columns(table, spec.force_identifier, "force", spec)
        torque = _columns(table, spec.torque_identifier, "torque", spec) if spec.torque_identifier else np.zeros_like(force)
        point = _columns(table, spec.point_identifier, "point", spec) if spec.point_identifier else None
        if point is not None:
            nan_rows = ~np.all(np.isfinite(point), axis=1)
            if np.any(nan_rows):
                if np.abs(force[nan_rows]).max() > 1e-6:
                    warnings.warn(f"{table.source}: ExternalForce '{spec.name}' has NaN points with nonzero "
                                  "force; those points are taken as zero", stacklevel=2)
                point = np.where(np.isfinite(point), point, 0.0)
        out.append(SampledLoad(
            spec, _interpolator(table.time, force)(times),
            None if point is None else _interpolator(table.time, point)(times),
            _interpolator(table.time, torque)(times)))
    return out

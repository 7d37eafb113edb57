"""A treatment solution's modeled ground reactions as OpenSim ExternalLoads.

A TO/VO/DO results folder holds ``GRFData/<trial>.sto``: per contact surface of the
``.osimx`` the modeled force (its ``force_columns``), the point it acts at (its
``electrical_center_columns``: the midfoot-superior marker projected to the resting spring
length) and the moment about that point (``moment_columns``), in ground. :func:`export_treatment_loads`
writes them as ``<name>.mot`` + ``<name>.xml`` (:mod:`nmsm.interop.external_loads`), each
surface applied to its hindfoot body, so OpenSim's Inverse Dynamics tool can be re-run on the
solution's ``IKData/<trial>.sto`` with a model that has no contact forces (``nmsm export
--no-contact``): hip, knee and ankle moments then equal the solution's (the toes joint's
differ, since the springs under the toes act on the toes body in nmsm).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from nmsm.errors import InputError
from nmsm.interop.external_loads import GroundReaction, write_external_loads
from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage
from nmsm.io.trials import find_trial_file


def solution_reactions(results: Path, osimx_path: Path, trial: str | None = None) -> list[GroundReaction]:
    """The modeled reactions of a treatment results folder, one per contact surface."""
    folder = Path(results) / "GRFData"
    if not folder.is_dir():
        raise InputError("no GRFData folder (a treatment solution with foot contact writes one)", file=results,
                         expected="a TO, VO or DO results folder of a model with contact surfaces")
    files = sorted(p for p in folder.glob("*.sto") if p.stem != "CoP")
    path = find_trial_file(folder, trial) if trial else (files[0] if len(files) == 1 else None)
    if path is None:
        raise InputError(f"{len(files)} ground-reaction files", file=folder, expected="one, or name the trial")
    surfaces = read_osimx(osimx_path).contact_surfaces
    if not surfaces:
        raise InputError("the .osimx has no contact surface", file=osimx_path, element="<RCNLContactSurfaceSet>",
                         expected="GCP's contact surfaces")
    table = read_storage(path, allow_nan=lambda label: True)
    out = []
    for k, surface in enumerate(surfaces, start=1):
        missing = [c for c in (*surface.force_columns, *surface.electrical_center_columns, *surface.moment_columns)
                   if not table.has(c)]
        if missing:
            raise InputError(f"columns {', '.join(missing)} of contact surface {k} are missing", file=path,
                             element="column labels", expected="the .osimx surface's force, center and moment columns")
        force = table.columns(list(surface.force_columns))
        point = table.columns(list(surface.electrical_center_columns))
        moment = table.columns(list(surface.moment_columns))
        point = np.where(np.isfinite(point), point, 0.0)
        out.append(GroundReaction(f"{surface.hindfoot_body}_contact", surface.hindfoot_body, table.time, force, point,
                                  moment))
    return out


def export_treatment_loads(results: str | os.PathLike[str], osimx_path: str | os.PathLike[str],
                           output: str | os.PathLike[str], trial: str | None = None) -> tuple[Path, Path]:
    """Write ``output`` (.xml) and its ``.mot``; returns both paths."""
    reactions = solution_reactions(Path(results), Path(osimx_path), trial)
    return write_external_loads(Path(output).with_suffix(".xml"), reactions)

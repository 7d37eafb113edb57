"""Writing a finished GCP run into a staging folder (file list: :mod:`nmsm.tools.gcp.outputs`)."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import attrs
import numpy as np

from nmsm.io.osimx import OsimxModel, write_osimx
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.io.storage import write_storage
from nmsm.model.casadi_model import CasadiModel
from nmsm.tools.gcp import outputs, report
from nmsm.tools.gcp.data import full_coordinates
from nmsm.tools.gcp.ik_update import updated_motion
from nmsm.tools.gcp.inputs import FootInputs
from nmsm.tools.gcp.state import GcpState
from nmsm.tools.gcp.values import FootValues, as_array
from nmsm.tools.jmp.ik import motion_table


@attrs.frozen(eq=False)
class FootResult:
    """One foot's inputs, final values and the state of its group (``slot``: its position
    in that group)."""

    foot: FootInputs
    values: FootValues
    state: GcpState
    slot: int

    @property
    def correction(self) -> outputs.PlateCorrection:
        return outputs.PlateCorrection(self.state.electrical_center_shifts[self.slot],
                                       self.state.plate_rotations[self.slot], self.state.resting_spring_length)


def foot_results(groups: Sequence[Any]) -> list[FootResult]:
    """Every foot of the optimized groups (:class:`~nmsm.tools.gcp.run.GroupResult`)."""
    return [FootResult(f, v, g.state, i) for g in groups for i, (f, v) in enumerate(zip(g.feet, g.values))]


def write_results(stage: Path, settings: GroundContactPersonalizationSettings, groups: Sequence[Any],
                  casadi_model: CasadiModel, motion: Any, grf: Any, osimx: OsimxModel | None,
                  errors: dict[int, dict[str, float]], *, update_motion: bool) -> None:
    """Every result file of :mod:`nmsm.tools.gcp.outputs` into ``stage``."""
    prefix = settings.input_model_file.stem
    results = foot_results(groups)
    feet = [r.foot for r in results]
    values = [r.values for r in results]
    for r in results:
        outputs.write_foot_files(stage, prefix, r.foot, r.values, r.state)
    surfaces = [outputs.contact_surface(r.foot, r.state) for r in results]
    base_name = settings.input_osimx_file.stem if settings.input_osimx_file is not None else prefix
    document = outputs.osimx_model(osimx, casadi_model.model.name, str(settings.input_model_file), surfaces)
    write_osimx(stage / f"{base_name}_gcp.osimx", document)
    (stage / f"{prefix}_gcpErrors.txt").write_text(
        report.format_error_table({f"foot {k}": e for k, e in errors.items()}, "GCP RMS errors (nmsm)"), encoding="utf-8")
    if not outputs.same_window(feet):
        warnings.warn("feet have different time windows: combined GRFData/IKData files are not written",
                      stacklevel=2)
        return
    grf_name = Path(settings.input_grf_file.name)
    (stage / "GRFData").mkdir(exist_ok=True)
    modeled, modeled_cop = outputs.modeled_grf_tables(feet, values, [r.state.resting_spring_length for r in results])
    write_storage(stage / "GRFData" / f"gcp_modeled_{grf_name}", modeled)
    write_storage(stage / "GRFData" / f"gcp_modeled_{grf_name.stem}_CoP{grf_name.suffix}", modeled_cop)
    if any(task.electricalCenterX or task.electricalCenterY or task.electricalCenterZ or task.forcePlateRotation
           for task in settings.tasks):
        adjusted, adjusted_cop = outputs.adjusted_grf_tables(grf, feet, [r.correction for r in results])
        write_storage(stage / "GRFData" / f"gcp_adjusted{grf_name}", adjusted)
        write_storage(stage / "GRFData" / f"gcp_adjusted{grf_name.stem}_CoP{grf_name.suffix}", adjusted_cop)
    if update_motion:
        write_updated_motion(stage, settings, casadi_model, motion, feet, values)


def write_updated_motion(stage: Path, settings: GroundContactPersonalizationSettings, casadi_model: CasadiModel,
                         motion: Any, feet: Sequence[FootInputs], values: Sequence[FootValues]) -> None:
    """``IKData/gcp_modeled_<motion>`` (:mod:`nmsm.tools.gcp.ik_update`)."""
    times = feet[0].time
    rows = np.array([int(np.argmin(np.abs(motion.time - t))) for t in times])
    q_full = full_coordinates(motion, casadi_model.model, rows, feet[0].foot.hindfoot_body,
                              motion_file=settings.input_motion_file)
    targets: dict[str, np.ndarray] = {}
    for foot, v in zip(feet, values):
        markers = as_array(v.markers).T.reshape(foot.n_frames, 5, 3)
        for k, name in enumerate(foot.foot.markers.names()):
            targets[name] = markers[:, k, :]
    result = updated_motion(casadi_model, times, q_full, targets)
    (stage / "IKData").mkdir(exist_ok=True)
    write_storage(stage / "IKData" / f"gcp_modeled_{settings.input_motion_file.name}", motion_table(result),
                  name="Coordinates")

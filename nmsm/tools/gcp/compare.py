"""Score a finished GCP result (ours or the MATLAB original's) with nmsm's cost.

:func:`score_original` does it all for a results folder. A result is an ``.osimx``
(springs, spring constants, surface properties) plus each foot's
optimized kinematics file (``*_Foot_<n>_optimizedFootKinematics.sto``). The kinematics are
turned back into B-spline coefficients: the original's optimized kinematics are exactly
``N (base * C)`` on the same basis, so ``nodes = lstsq(N, q)`` and ``C = nodes / base``.
:func:`result_state` returns the matching :class:`~nmsm.tools.gcp.state.GcpState`; the
feet must be built with that ``.osimx``'s springs (``build_foot_inputs(..., osimx)``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import attrs
import numpy as np

from nmsm.errors import InputError
from nmsm.io.osimx import OsimxModel
from nmsm.io.storage import read_storage
from nmsm.tools.gcp import bspline
from nmsm.tools.gcp.inputs import FootInputs, matching_osimx_surface
from nmsm.tools.gcp.state import GcpState

#: smallest |base node| divided by: coefficients of (near) zero base nodes are set to 1
_TINY = 1e-12


def coefficients_from_kinematics(foot: FootInputs, coordinates: np.ndarray) -> tuple[np.ndarray, float]:
    """``(C (m, 7), max reconstruction error)`` of optimized foot coordinates (T, 7)."""
    nodes = bspline.fit_nodes(foot.basis, coordinates)
    base = foot.base_nodes
    safe = np.where(np.abs(base) > _TINY, base, 1.0)
    coefficients = np.where(np.abs(base) > _TINY, nodes / safe, 1.0)
    rebuilt = foot.basis @ (base * coefficients)
    return coefficients, float(np.abs(rebuilt - coordinates).max())


def result_state(osimx: OsimxModel, kinematics_files: Sequence[Path], feet: Sequence[FootInputs]) -> GcpState:
    """The :class:`GcpState` of a finished result (module docstring). Electrical-center
    shifts and plate rotations are not stored in an ``.osimx``: they are 0."""
    surfaces = [matching_osimx_surface(osimx, f.surface) for f in feet]
    if any(s is None for s in surfaces):
        raise InputError("the result has no contact surface for every foot", expected="one surface per hindfoot body")
    first = surfaces[0]
    coefficients = []
    for foot, path in zip(feet, kinematics_files):
        table = read_storage(path)
        if table.n_rows != foot.n_frames or np.abs(table.time - foot.time).max() > 1e-6:
            raise InputError(f"{table.n_rows} frames, foot window has {foot.n_frames}", file=path,
                             expected="the foot's time window")
        c, _ = coefficients_from_kinematics(foot, table.data[:, :7])
        coefficients.append(c)
    return GcpState(
        spring_constants=np.array([s.spring_constant for s in first.springs], dtype=float),
        damping_factor=first.damping_factor,
        dynamic_friction_coefficient=first.dynamic_friction_coefficient,
        viscous_friction_coefficient=first.viscous_friction_coefficient,
        resting_spring_length=first.resting_spring_length,
        latching_velocity=first.latching_velocity,
        coefficients=coefficients,
        electrical_center_shifts=[np.zeros(3) for _ in feet],
        plate_rotations=[0.0 for _ in feet],
    )


def shifts_from_adjusted_grf(adjusted: Path, feet: Sequence[FootInputs]) -> list[np.ndarray]:
    """Electrical-center shifts (3,) m per foot recovered from an adjusted GRF file (the
    original's ``GRFData/updated_<grf>``: the input file with shifted center columns)."""
    table = read_storage(adjusted, allow_nan=lambda label: True)
    shifts = []
    for foot in feet:
        rows = np.array([int(np.argmin(np.abs(table.time - t))) for t in foot.time])
        centers = table.columns(list(foot.surface.electrical_center_columns))[rows]
        shift = np.nanmedian(centers - foot.reactions.electrical_center, axis=0)
        shifts.append(np.where(np.isfinite(shift), shift, 0.0))
    return shifts


@attrs.frozen(eq=False)
class ScoredResult:
    """A finished result scored by nmsm: last task's ``cost`` and ``term_costs``, the RMS
    error table per foot index (:mod:`nmsm.tools.gcp.report`) and the recovered state."""

    cost: float
    term_costs: dict[str, float]
    errors: dict[int, dict[str, float]]
    state: GcpState


def score_original(settings_file: Path, results: Path) -> ScoredResult:
    """Score the result folder ``results`` (its ``*.osimx``, ``*_Foot_<n>_optimizedFootKinematics.sto``
    and, when present, the adjusted GRF file ``GRFData/updated_<grf>`` or
    ``GRFData/gcp_adjusted<grf>`` giving electrical-center shifts) with the cost of the last
    task of ``settings_file``, all feet together."""
    from nmsm.core.registry import build_terms
    from nmsm.io.osimx import read_osimx
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
    from nmsm.tools.gcp.problem import build_task_problem
    from nmsm.tools.gcp.report import rms_errors
    from nmsm.tools.gcp.run import load_feet
    from nmsm.tools.gcp.values import foot_values

    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(settings_file))
    results = Path(results)
    osimx_files = sorted(results.glob("*.osimx"))
    if not osimx_files:
        raise InputError("no .osimx in the results folder", file=results, expected="a GCP results folder")
    feet, *_ = load_feet(settings, spring_locations=osimx_files[0])
    kinematics = []
    for foot in feet:
        found = sorted(results.glob(f"*_Foot_{foot.index}_optimizedFootKinematics.sto"))
        if not found:
            raise InputError(f"no optimized kinematics of foot {foot.index}", file=results,
                             expected=f"*_Foot_{foot.index}_optimizedFootKinematics.sto")
        kinematics.append(found[0])
    state = result_state(read_osimx(osimx_files[0]), kinematics, feet)
    grf_name = settings.input_grf_file.name
    for candidate in (results / "GRFData" / f"updated_{grf_name}", results / "GRFData" / f"gcp_adjusted{grf_name}"):
        if candidate.is_file():
            state.electrical_center_shifts = shifts_from_adjusted_grf(candidate, feet)
            break
    task = settings.tasks[-1]
    built = build_task_problem(feet, state, task, build_terms(list(task.cost_terms), "GCP"))
    term_costs = built.problem.term_costs(built.problem.initial_scaled())
    design = state.design()
    errors = {f.index: rms_errors(f, foot_values(f, design, i)) for i, f in enumerate(feet)}
    return ScoredResult(float(sum(term_costs.values())), term_costs, errors, state)

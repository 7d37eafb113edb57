"""The optimal control solver settings file, as nmsm applies it.

Honoured: the mesh (``setup_mesh_phase_intervals`` x ``setup_mesh_phase_colpoints_per_Interval``
LGR points), ``setup_nlp_max_iterations``, ``setup_nlp_tolerance`` (IPOPT ``tol`` on the objective
normalized by its initial value - see ``TreatmentOptions.objective_scaling`` - capped at
:data:`MAX_TOLERANCE`, for Design Optimization at :data:`DESIGN_MAX_TOLERANCE`, with a
warning: the tutorials' value 1 lets IPOPT stop within a few iterations far from the
optimum, e.g. 2.3 times the original's cost on TorqueTOSettingsV2),
``setup_nlp_linear_solver`` (HSL solvers fall back to MUMPS with a warning when HSL is not
installed), ``setup_display_level`` (0: silent). Not applicable to nmsm, reported in one
warning when they would change GPOPS-II's behaviour: the derivative options (nmsm's
derivatives are exact, first and second order, from CasADi), ``setup_scales_method``
(variables are always scaled by their bounds), ``setup_mesh_method`` other than ``none``
and the mesh-refinement parameters (the mesh is fixed), ``setup_nlp_solver`` ``snopt``
(IPOPT is used), ``integral_bound`` (nmsm puts no bounds on cost integrals, so a guess
with a large initial cost is not infeasible). ``setup_method`` RPM-Integration and
RPM-Differentiation are the same discrete problem; nmsm uses the differentiation form.
"""

from __future__ import annotations

import warnings
from typing import Any

import attrs

from nmsm.core.transcription.mesh import Mesh


#: loosest IPOPT ``tol`` nmsm applies (on the normalized objective)
MAX_TOLERANCE = 1e-2

#: loosest IPOPT ``tol`` of Design Optimization. A design goal (e.g. the final toe speed)
#: makes the objective at the guess orders of magnitude above its optimum, so
#: :data:`MAX_TOLERANCE` of the normalized objective stops IPOPT before the optimum; TO and VO
#: keep :data:`MAX_TOLERANCE`, where a tighter one gains little and costs iterations (the
#: measurements: docs/developing.md, "Treatment: measurements and audit trail").
DESIGN_MAX_TOLERANCE = 1e-6


@attrs.frozen
class SolverPlan:
    """Mesh and IPOPT options derived from the solver settings."""

    mesh: Mesh
    ipopt: dict[str, Any]
    not_applicable: tuple[str, ...]


def plan_from_settings(gpops: Any, *, source: str = "", max_tolerance: float = MAX_TOLERANCE) -> SolverPlan:
    """Mesh and IPOPT options of a :class:`nmsm.io.settings.solver.GpopsSettings`; warns
    once about options set away from their defaults that do not apply (see module docstring;
    a file that leaves them at their defaults gets no warning). ``max_tolerance``: the loosest
    ``tol`` applied (:data:`MAX_TOLERANCE`, or :data:`DESIGN_MAX_TOLERANCE` for a DO)."""
    mesh = Mesh.uniform(int(gpops.setup_mesh_phase_intervals), int(gpops.setup_mesh_phase_colpoints_per_Interval))
    display = int(gpops.setup_display_level)
    where = f"{source}: " if source else ""
    tol = float(gpops.setup_nlp_tolerance)
    if tol > max_tolerance:
        warnings.warn(f"{where}setup_nlp_tolerance={tol:g} is looser than nmsm applies; IPOPT uses tol={max_tolerance:g} "
                      "on the objective normalized by its initial value (pass tolerance= to override)", stacklevel=2)
        tol = max_tolerance
    ipopt = {
        "max_iter": int(gpops.setup_nlp_max_iterations),
        "tol": tol,
        "linear_solver": str(gpops.setup_nlp_linear_solver),
        "print_level": 0 if display == 0 else (3 if display == 1 else 5),
        "hessian": str(gpops.hessian_approximation),
    }
    ignored = []  # options set away from their defaults that nmsm cannot honour
    if gpops.setup_derivatives_supplier != "sparseFD":
        ignored.append(f"setup_derivatives_supplier={gpops.setup_derivatives_supplier} (derivatives are exact, "
                       "from CasADi)")
    if float(gpops.integral_bound) != 1.0:
        ignored.append(f"integral_bound={gpops.integral_bound} (cost integrals are not bounded)")
    if gpops.setup_scales_method != "none":
        ignored.append(f"setup_scales_method={gpops.setup_scales_method} (variables are scaled by their bounds)")
    if gpops.setup_mesh_method != "none" and int(gpops.setup_mesh_max_iterations) > 0:
        ignored.append(f"setup_mesh_method={gpops.setup_mesh_method} (no mesh refinement: the initial mesh is used)")
    if gpops.setup_nlp_solver != "ipopt":
        ignored.append(f"setup_nlp_solver={gpops.setup_nlp_solver} (IPOPT is used)")
    if ignored:
        warnings.warn(where + "GPOPS-II options without effect in nmsm: " + "; ".join(ignored), stacklevel=2)
    return SolverPlan(mesh, ipopt, tuple(ignored))

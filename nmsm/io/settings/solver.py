"""Optimal control solver settings (``<OptimalControlSolverSettings><GpopsSettings>``).

The element names are GPOPS-II's ``setup`` fields; nmsm's collocation back end reads the
mesh (intervals x points per interval), the NLP options and ``integral_bound``.
``<MocoSettings>`` is recognized, as in the original, but not implemented.
"""

from __future__ import annotations

from typing import Any

import attrs

from nmsm.io.settings.document import SettingsDocument
from nmsm.io.settings.schema import ReadContext, at_least_one, non_negative, positive, read_block, setting

TOOL_ELEMENT = "OptimalControlSolverSettings"


@attrs.frozen(kw_only=True)
class GpopsSettings:
    """``<GpopsSettings>``."""

    setup_derivatives_supplier: str = setting(
        "setup_derivatives_supplier",
        kind="text",
        default="sparseFD",
        choices=("sparseFD", "sparseBD", "sparseCD", "adigator"),
        doc="Derivative supplier: sparseFD, sparseBD, sparseCD or adigator (nmsm uses exact CasADi derivatives)",
    )
    setup_derivatives_level: str = setting(
        "setup_derivatives_level",
        kind="text",
        default="first",
        choices=("first", "second"),
        doc="Derivative level: first or second",
    )
    setup_derivatives_dependencies: str = setting(
        "setup_derivatives_dependencies",
        kind="text",
        default="sparse",
        choices=("sparse", "sparseNaN", "full"),
        doc="Derivative dependencies: sparse, sparseNaN or full",
    )
    setup_derivatives_step_size: float = setting(
        "setup_derivatives_step_size", kind="number", default=1e-8, check=positive, doc="Finite-difference step"
    )
    setup_scales_method: str = setting(
        "setup_scales_method",
        kind="text",
        default="none",
        choices=(
            "none",
            "automatic-bounds",
            "automatic-guess",
            "automatic-guessUpdate",
            "automatic-hybrid",
            "automatic-hybridUpdate",
        ),
        doc="Scaling method (nmsm always scales by the variable bounds)",
    )
    setup_method: str = setting(
        "setup_method",
        kind="text",
        default="RPM-Differentiation",
        choices=("RPM-Differentiation", "RPM-Integration"),
        doc="Collocation form: RPM-Differentiation or RPM-Integration",
    )
    setup_mesh_method: str = setting(
        "setup_mesh_method",
        kind="text",
        default="hp-PattersonRao",
        choices=("hp-PattersonRao", "none", "hp-DarbyRao", "hp-LiuRao", "hp-LiuRao-Legendre"),
        doc="Mesh refinement method (none: a fixed mesh)",
    )
    setup_mesh_tolerance: float = setting(
        "setup_mesh_tolerance", kind="number", default=1e-2, check=positive, doc="Mesh refinement tolerance"
    )
    setup_mesh_max_iterations: int = setting(
        "setup_mesh_max_iterations", kind="integer", default=10, check=non_negative, doc="Mesh refinement iterations"
    )
    setup_mesh_colpoints_min: int = setting(
        "setup_mesh_colpoints_min",
        kind="integer",
        default=3,
        check=at_least_one,
        doc="Fewest points per interval during refinement",
    )
    setup_mesh_colpoints_max: int = setting(
        "setup_mesh_colpoints_max",
        kind="integer",
        default=10,
        check=at_least_one,
        doc="Most points per interval during refinement",
    )
    setup_mesh_splitmult: float = setting(
        "setup_mesh_splitmult", kind="number", default=1.2, check=positive, doc="Mesh refinement split multiplier"
    )
    setup_mesh_curveratio: float = setting(
        "setup_mesh_curveratio", kind="number", default=2.0, check=positive, doc="Mesh refinement curvature ratio"
    )
    setup_mesh_R: float = setting("setup_mesh_R", kind="number", default=1.2, check=positive, doc="Mesh refinement R")
    setup_mesh_sigma: float = setting(
        "setup_mesh_sigma", kind="number", default=0.5, check=positive, doc="Mesh refinement sigma"
    )
    setup_mesh_phase_intervals: int = setting(
        "setup_mesh_phase_intervals", kind="integer", default=6, check=at_least_one, doc="Number of mesh intervals"
    )
    setup_mesh_phase_colpoints_per_Interval: int = setting(
        "setup_mesh_phase_colpoints_per_Interval",
        kind="integer",
        default=10,
        check=at_least_one,
        doc="Collocation points per interval",
    )
    setup_nlp_solver: str = setting(
        "setup_nlp_solver", kind="text", default="ipopt", choices=("ipopt", "snopt"), doc="NLP solver: ipopt or snopt"
    )
    setup_nlp_linear_solver: str = setting(
        "setup_nlp_linear_solver",
        kind="text",
        default="ma57",
        choices=("ma57", "mumps"),
        doc="IPOPT linear solver: ma57 or mumps (MUMPS is used when HSL is not installed)",
    )
    setup_nlp_tolerance: float = setting(
        "setup_nlp_tolerance", kind="number", default=1e-3, check=positive, doc="NLP tolerance"
    )
    setup_nlp_max_iterations: int = setting(
        "setup_nlp_max_iterations", kind="integer", default=20000, check=at_least_one, doc="NLP iterations"
    )
    hessian_approximation: str = setting(
        "hessian_approximation",
        kind="text",
        default="exact",
        choices=("exact", "limited-memory"),
        doc="nmsm's choice of IPOPT's Lagrangian Hessian: exact (second derivatives by automatic "
            "differentiation) or limited-memory (L-BFGS from first derivatives, as GPOPS-II's first "
            "derivative level gives IPOPT)",
    )
    setup_display_level: int = setting(
        "setup_display_level", kind="integer", default=2, check=non_negative, doc="Solver output level"
    )
    integral_bound: float = setting(
        "integral_bound", kind="number", default=1.0, check=positive, doc="Upper bound of each cost integral"
    )

    @property
    def collocation_points(self) -> int:
        """Total collocation points of the initial mesh (intervals x points per interval)."""
        return self.setup_mesh_phase_intervals * self.setup_mesh_phase_colpoints_per_Interval


@attrs.frozen(kw_only=True)
class OptimalControlSolverSettings:
    """Validated solver settings."""

    gpops: GpopsSettings = setting(
        "GpopsSettings", kind="block", nested=GpopsSettings, required=True, doc="GPOPS-II style settings"
    )

    @classmethod
    def validate(cls, values: dict[str, Any], ctx: ReadContext) -> None:
        if ctx.child("MocoSettings") is not None:
            raise ctx.error(
                "MocoSettings",
                "<MocoSettings> is recognized but not implemented (as in the original)",
                "<GpopsSettings>",
            )

    OTHER_ELEMENTS = ("MocoSettings",)

    @classmethod
    def from_document(cls, doc: SettingsDocument) -> OptimalControlSolverSettings:
        doc.require_tool(TOOL_ELEMENT)
        return read_block(cls, doc, doc.tool_element)

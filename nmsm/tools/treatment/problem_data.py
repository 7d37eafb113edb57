"""Everything a treatment problem is built from, once files are read (no CasADi variables).

:class:`TreatmentData` is what :mod:`nmsm.tools.treatment.formulation` turns into an
OptimizationProblem and what the context reads references from. Tests build it directly
around small synthetic models; the tools build it from settings files
(:mod:`nmsm.tools.treatment.inputs`).
"""

from __future__ import annotations

from typing import Any

import attrs
import casadi as cs
import numpy as np

from nmsm.core.ocp_model import TreatmentModel
from nmsm.core.splines import ReferenceSplines


@attrs.define
class TreatmentData:
    """Inputs of one TO/VO/DO problem.

    ``references``: ``"coordinates"`` (tracked IK of the model's coordinates, rad|m),
    ``"loads"`` (tracked ID, N·m|N), ``"activations"`` (reference muscle activations), ...
    ``prescribed``: splines of the coordinates that are not states (usually the tracked IK).
    ``state_guess``: (K + 1, 2 n_s) [q, q̇] on the mesh nodes and ``acceleration_guess``
    (K, n_s) on the collocation points are filled by the tool from the initial-guess data.
    Times: references are sampled at ``s * reference_duration`` (normalized time ``s``).
    """

    tool: str
    model: TreatmentModel
    state_coordinates: tuple[str, ...]
    references: dict[str, ReferenceSplines]
    prescribed: ReferenceSplines
    reference_duration: float
    final_time_guess: float
    final_time_bounds: tuple[float, float]
    controllers: list[Any] = attrs.field(factory=list)
    contact_models: list[Any] = attrs.field(factory=list)
    parameters: dict[str, cs.MX] = attrs.field(factory=dict)
    #: (n_p, 1) values of the model's parameters (``model.parameter_count`` > 0: joint-frame
    #: model functions of Design Optimization), expressions of ``parameters``; None otherwise
    model_parameter_values: cs.MX | None = None
    acceleration_control_offset: int = 0
    #: free final time: scale prescribed coordinates' speeds by T_ref/t_f and accelerations by
    #: (T_ref/t_f)^2 (physically consistent time warping). False reproduces the original,
    #: which warps their positions to the new duration but keeps the data's speeds.
    rescale_prescribed_derivatives: bool = True
    _tracked_cache: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = attrs.field(factory=dict, repr=False)

    @property
    def free_final_time(self) -> bool:
        return self.final_time_bounds[1] > self.final_time_bounds[0]

    def tracked_full_kinematics(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, q̇, q̈) of every model coordinate (n, nq) on the tracked kinematics at ``times``.

        Independent coordinates come from the ``coordinates`` reference; coupler-dependent
        ones are computed through the model (never read from the data).
        """
        times = np.asarray(times, dtype=float).ravel()
        key = times.tobytes()
        if key not in self._tracked_cache:
            refs = self.references["coordinates"]
            independent = self.model.independent_coordinates
            values = [refs.values(times, order, independent) for order in range(3)]
            if tuple(independent) == tuple(self.model.coordinate_names):
                full = values
            else:
                f = self.model.expand_function().map(times.size)
                out = f(*(cs.DM(v).T for v in values))
                full = [np.asarray(cs.DM(o).T) for o in out]
            self._tracked_cache[key] = (np.asarray(full[0]), np.asarray(full[1]), np.asarray(full[2]))
        return self._tracked_cache[key]

"""A small Treatment Optimization problem on a two-link pendulum (:class:`nmsm.examples.pendulum.Pendulum`,
one coupled coordinate), with consistent tracked data, for checking terms (:func:`nmsm.testing.check_term`).

States ``q0``, ``q1`` (and speeds) start on the tracked motion; torque controls on ``q0`` and
``q1`` start on the tracked inverse dynamics; 5 mesh intervals of 5 collocation points; 1 s.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from nmsm.core.bounds import RangeRule, range_bounds
from nmsm.examples.pendulum import Pendulum
from nmsm.core.controller_setup import ControllerSetup
from nmsm.tools.treatment.formulation import StateSetup, TreatmentProblem, build_problem
from nmsm.tools.treatment.problem_data import TreatmentData
from nmsm.core.splines import ReferenceSplines
from nmsm.core.transcription.mesh import Mesh

#: duration of the movement (s)
DURATION = 1.0


def reference_data(model: Pendulum, n_frames: int = 61) -> tuple[ReferenceSplines, ReferenceSplines]:
    """Tracked kinematics and their exact inverse dynamics (consistent data)."""
    t = np.linspace(0, DURATION, n_frames)
    q = model.motion(t)
    ind = ReferenceSplines(t, model.independent_coordinates, q)
    Q, Qd, Qdd = model.full_kinematics(q, ind.values(t, 1), ind.values(t, 2))
    tau = model.inverse_dynamics(Q, Qd, Qdd)
    loads = ReferenceSplines(t, tuple(model.load_label(c) for c in model.coordinate_names), tau)
    return ind, loads


def build_pendulum_problem(terms: Sequence[Any], *, tool: str = "TO", model: Pendulum | None = None,
                           mesh: Mesh | None = None, states: Sequence[str] = ("q0", "q1"),
                           torque: Sequence[str] = ("q0", "q1"), guess_scale: float = 1.0,
                           final_time: tuple[float, float] | None = None, initial_guess: dict | None = None,
                           controls_guess: dict | None = None) -> TreatmentProblem:
    """The problem with ``terms``; ``guess_scale`` scales the starting states (1: the tracked motion)."""
    from nmsm.core.registry import get_registry

    model = model or Pendulum(n=2, coupler_ratio=0.3)
    mesh = mesh or Mesh.uniform(5, 5)
    coords, loads = reference_data(model)
    refs = {"coordinates": coords, "loads": loads}
    lo_t, hi_t = final_time or (DURATION, DURATION)
    s_col = mesh.times("collocation")
    setup = ControllerSetup(tool, model, s_col * DURATION, DURATION, refs, initial_guess or {"loads": loads},
                            guess=controls_guess)
    data = TreatmentData(tool, model, tuple(states), refs, coords, DURATION, DURATION, (lo_t, hi_t))
    if torque:
        controller = get_registry().get("controller", "torque", tool)
        data.controllers = [controller.from_settings({"coordinate_list": " ".join(torque)}, setup)]
    t = coords.time
    lo_q, hi_q = range_bounds(coords.values(t, 0, states), RangeRule(2))
    lo_v, hi_v = range_bounds(coords.values(t, 1, states), RangeRule(1.5))
    lo_a, hi_a = range_bounds(coords.values(t, 2, states), RangeRule(1))
    tn = mesh.times("nodes") * DURATION
    guess = np.hstack([coords.values(tn, 0, states), coords.values(tn, 1, states)]) * guess_scale
    ss = StateSetup(np.r_[lo_q, lo_v], np.r_[hi_q, hi_v], lo_a, hi_a, guess,
                    coords.values(s_col * DURATION, 2, states) * guess_scale)
    return build_problem(data, mesh, ss, list(terms))

"""Inverse kinematics and Joint Model Personalization (JMP).

Public API (imported lazily: importing this package loads no CasADi)::

    from nmsm.tools.jmp import inverse_kinematics, run_ik_files, write_motion, run_settings

    ik = inverse_kinematics("model.osim", "trial.trc", weights={"R_Heel": 1.0, ...})
    ik.q                     # (F, n) every coordinate, rad / m;  ik.marker_errors (F, M) m
    write_motion("trial_ik.mot", ik)

    run = run_settings("JMPSettings.xml", results_directory="out")
    run.output_model         # the personalized .osim

Modules (one job each): ``ik`` (per-frame IK), ``ik_settings`` (OpenSim IK settings files),
``marker_data`` (markers, frames, gaps, units), ``marker_model`` (markers as CasADi functions
of free coordinates and model parameters), ``dense_evaluator`` (CasADi calls on numpy
buffers), ``design`` (a task's design variables and bounds), ``problem`` (one task as one
least-squares problem over all frames and the parameters, a
:class:`~nmsm.core.residual_problem.ResidualProblem` solved by the ``levenberg_marquardt``
back end), ``model_output`` (writing the
personalized ``.osim``), ``task`` (one task end to end), ``report``, ``run`` (settings file
to results folder), ``cli`` (``nmsm ik``).
"""

from __future__ import annotations

from typing import Any

_EXPORTS = {
    "inverse_kinematics": "nmsm.tools.jmp.ik",
    "run_ik_files": "nmsm.tools.jmp.ik",
    "write_motion": "nmsm.tools.jmp.ik",
    "IkResult": "nmsm.tools.jmp.ik",
    "run_settings": "nmsm.tools.jmp.run",
    "JmpRun": "nmsm.tools.jmp.run",
}

__all__ = list(_EXPORTS)


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'nmsm.tools.jmp' has no attribute '{name}'")
    import importlib

    return getattr(importlib.import_module(module), name)

"""Muscle-driven controllers on the synergy kicking tutorial (evaluated, not solved)."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import casadi as cs
import numpy as np

from nmsm.io.storage import read_storage
from nmsm.tools.treatment.modifiers import ModificationTarget
from nmsm.tools.treatment.run import load_settings
from nmsm.tools.treatment.tool import TreatmentOptions, prepare

SURROGATE = {
    "surrogate_model_coordinate_list": "hip_flexion_r hip_adduction_r hip_rotation_r knee_angle_r ankle_angle_r "
                                       "subtalar_angle_r",
}


class _WithMuscleController:
    """A TO settings object whose controller is the individual muscle controller."""

    def __init__(self, settings: Any, folder: Path) -> None:
        self._settings = settings
        self.synergy_controller = None
        self.muscle_controller = {**SURROGATE, "surrogate_model_data_directory": str(folder / "surrogateData")}

    def __getattr__(self, name: str) -> Any:
        return getattr(self._settings, name)


def _folder(shared: Path) -> Path:
    return shared / "treatment" / "synergy_kick_tutorial"


def _at_start(built: Any, expression: Any) -> np.ndarray:
    problem = built.problem
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    return np.asarray(problem.evaluate(cs.MX(expression), x0))


def test_individual_muscle_controller(shared_data: Path) -> None:
    folder = _folder(shared_data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(folder / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml")
        prepared = prepare(_WithMuscleController(settings, folder), solver, TreatmentOptions())
    ctx = prepared.built.context
    assert "bflh_r" in ctx.controller_names and ctx.is_actuated("knee_angle_r")
    # the guess is NCP's combined activations, sampled at the collocation points
    reference = read_storage(folder / "ncpResults" / "drive_kick1_combinedActivations.sto")
    activations = _at_start(prepared.built, ctx.muscle_activations())
    t = ctx.normalized_time * ctx.reference_duration
    expected = np.clip(np.column_stack([np.interp(t, reference.time, reference.column(m)) for m in ctx.muscle_names]),
                       0.01, 1.0)
    assert np.max(np.abs(activations - expected)) < 0.02
    moments = _at_start(prepared.built, ctx.controller_load("knee_angle_r_moment"))
    assert np.all(np.isfinite(moments)) and np.max(np.abs(moments)) > 1.0


def test_strength_modifier_scales_muscle_moments(shared_data: Path) -> None:
    folder = _folder(shared_data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(folder / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml")

        def halve_every_strength(problem: Any, data: Any) -> None:
            target = ModificationTarget(data, settings)
            for muscle in target.muscle_names:
                target.set_muscle_parameter(muscle, "max_isometric_force",
                                            0.5 * target.muscle_parameter(muscle, "max_isometric_force"))

        plain = prepare(settings, solver, TreatmentOptions())
        weak = prepare(settings, solver, TreatmentOptions(), declare_extra=halve_every_strength)
    load = "knee_angle_r_moment"
    strong = _at_start(plain.built, plain.built.context.controller_load(load))
    halved = _at_start(weak.built, weak.built.context.controller_load(load))
    assert np.allclose(halved, 0.5 * strong, rtol=1e-10, atol=1e-12)


def test_surrogate_model_file_name_is_honoured(shared_data: Path, tmp_path: Path) -> None:
    """``<surrogate_model_file_name>`` names the saved surrogate (as JSON next to the settings
    file): saved under that name, then loaded from it without a refit (it was always
    ``surrogateMuscles.json`` in the treatment tools)."""
    import shutil

    from nmsm.model.surrogate_fitting import _SURROGATE_CACHE

    folder = tmp_path / "kick"
    shutil.copytree(_folder(shared_data), folder)
    for path in [folder, *folder.rglob("*")]:
        path.chmod(path.stat().st_mode | 0o200)
    original = folder / "CompletedSettingsFiles" / "SynergyTOSettingsV1.xml"
    text = original.read_text()
    assert "<load_surrogate_model>true</load_surrogate_model>" in text
    saving = original.with_name("save.xml")
    saving.write_text(text.replace("<load_surrogate_model>true</load_surrogate_model>",
                                   "<load_surrogate_model>false</load_surrogate_model>")
                      .replace("<save_surrogate_model>false</save_surrogate_model>",
                               "<save_surrogate_model>true</save_surrogate_model>"
                               "<surrogate_model_file_name>kickSurrogate.mat</surrogate_model_file_name>"))
    loading = original.with_name("load.xml")
    loading.write_text(text.replace("<save_surrogate_model>false</save_surrogate_model>",
                                    "<save_surrogate_model>false</save_surrogate_model>"
                                    "<surrogate_model_file_name>kickSurrogate.mat</surrogate_model_file_name>"))
    _SURROGATE_CACHE.clear()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        settings, solver = load_settings(saving)
        prepare(settings, solver, TreatmentOptions())
    saved = folder / "CompletedSettingsFiles" / "kickSurrogate.json"
    assert saved.is_file() and not (folder / "CompletedSettingsFiles" / "surrogateMuscles.json").exists()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        settings, solver = load_settings(loading)
        prepare(settings, solver, TreatmentOptions())
    assert not [w for w in caught if "fitting a new surrogate" in str(w.message)]

"""The written model: body scaling as OpenSim's Model.scale, markers kept, kinematics consistent."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.io.settings.jmp import JmpBody, JmpFrame, JmpJoint, JmpTask
from nmsm.model import load_model
from nmsm.tools.jmp.design import build_design
from nmsm.tools.jmp.marker_model import MarkerKinematics
from nmsm.tools.jmp.model_output import write_task_model

MODEL = "jmp/uf_subject3_tutorial/CompletedSettingsFiles/UF_Subject_3_Scaled.osim"


def _task(anatomical: bool) -> JmpTask:
    frame = JmpFrame(translation=(False, False, False), orientation=(True, True, False), orientation_bounds=0.5)
    fixed = JmpFrame(translation=(False, False, False), orientation=(False, False, False))
    return JmpTask(is_enabled=True, marker_file_name=Path("unused.trc"), anatomical_markers=anatomical,
                   joints=(JmpJoint(name="knee_r", parent_frame_transformation=frame,
                                    child_frame_transformation=fixed),),
                   bodies=(JmpBody(name="pelvis", scale_body=True, move_markers=(False, False, False)),
                           JmpBody(name="tibia_r", scale_body=False, move_markers=(True, False, True))))


@pytest.mark.parametrize("anatomical", [False, True])
def test_written_model_has_the_optimized_kinematics(shared_data, tmp_path, anatomical):
    model = load_model(shared_data / MODEL)
    design = build_design(model, _task(anatomical), model.marker_names)
    labels = [v.label for v in design.variables]
    assert labels == ["knee_r parent orientation x", "knee_r parent orientation y", "pelvis scale",
                      "R_Shank_Superior location x", "R_Shank_Superior location z", "R_Shank_Inferior location x",
                      "R_Shank_Inferior location z", "R_Shank_Lateral location x", "R_Shank_Lateral location z",
                      "R_Ankle_Lateral location x", "R_Ankle_Lateral location z", "R_Ankle_Medial location x",
                      "R_Ankle_Medial location z"]
    values = design.initial + np.array([0.05, -0.03, 0.04] + [0.004, -0.003] * 5)
    out = tmp_path / "written.osim"
    write_task_model(model, shared_data / MODEL, design, values, out, anatomical_markers=anatomical)
    written = load_model(out)
    parameterized = MarkerKinematics(model, model.marker_names, design.parameters,
                                     unscaled_marker_bodies=design.unscaled_marker_bodies)
    plain = MarkerKinematics(written, written.marker_names)
    assert plain.free_names == parameterized.free_names
    rng = np.random.default_rng(1)
    q = parameterized.initial_free() + rng.uniform(-0.3, 0.3, size=(4, parameterized.n_free))
    q = np.clip(q, parameterized.lower, parameterized.upper)
    np.testing.assert_allclose(plain.marker_positions(q), parameterized.marker_positions(q, values), atol=1e-12)
    pelvis_markers = [m for m in model.markers if m.body == "pelvis"]
    for marker in pelvis_markers:
        expected = marker.location * (1.04 if anatomical else 1.0)
        np.testing.assert_allclose(written.marker(marker.name).location, expected, atol=1e-15)


def test_body_scaling_matches_opensim_model_scale(shared_data, tmp_path, bridge):
    model = load_model(shared_data / MODEL)
    task = JmpTask(is_enabled=True, marker_file_name=Path("unused.trc"),
                   bodies=(JmpBody(name="pelvis", scale_body=True, move_markers=(False, False, False)),))
    design = build_design(model, task, model.marker_names)
    ours_file = tmp_path / "ours.osim"
    notes = write_task_model(model, shared_data / MODEL, design, np.array([1.04]), ours_file,
                             anatomical_markers=True)
    assert any("rescaled by OpenSim" in n for n in notes)
    reply = bridge.call("opensim_scale_bodies", model=str(shared_data / MODEL), output=str(tmp_path / "os.osim"),
                        factors={"pelvis": 1.04})
    ours, theirs = load_model(ours_file), load_model(reply["output"])
    for path, frame in theirs.frames.items():
        np.testing.assert_allclose(ours.frames[path].translation, frame.translation, atol=1e-12, err_msg=path)
        np.testing.assert_allclose(ours.frames[path].orientation, frame.orientation, atol=1e-12, err_msg=path)
    for marker in theirs.markers:
        np.testing.assert_allclose(ours.marker(marker.name).location, marker.location, atol=1e-12)
    for name, body in theirs.bodies.items():
        assert ours.bodies[name].mass == pytest.approx(body.mass, rel=1e-12)
        np.testing.assert_allclose(ours.bodies[name].mass_center, body.mass_center, atol=1e-12)
        np.testing.assert_allclose(ours.bodies[name].inertia, body.inertia, rtol=1e-9, atol=1e-12)
    for name, wrap in theirs.wrap_objects.items():
        np.testing.assert_allclose(ours.wrap_objects[name].translation, wrap.translation, atol=1e-12)
        for key, value in wrap.parameters.items():
            np.testing.assert_allclose(ours.wrap_objects[name].parameters[key], value, rtol=1e-12, err_msg=name)
    changed = 0
    for muscle in theirs.muscles:
        mine = ours.muscle(muscle.name)
        assert mine.optimal_fiber_length == pytest.approx(muscle.optimal_fiber_length, rel=1e-12)
        assert mine.tendon_slack_length == pytest.approx(muscle.tendon_slack_length, rel=1e-12)
        for a, b in zip(mine.geometry.points, muscle.geometry.points):
            np.testing.assert_allclose(a.location, b.location, atol=1e-12)
        changed += mine.optimal_fiber_length != model.muscle(muscle.name).optimal_fiber_length
    assert changed > 20  # muscles crossing the pelvis changed length

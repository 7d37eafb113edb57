"""JMP returns the truth on a full-body model with perfect markers (RCNL2024, both knees).

Markers come from ``nmsm markers`` on the tutorial's gait trial mapped onto RCNL2024, with
both knee angles lowered by 2 deg and held at their range limit where that goes below it (a
straight knee touches its limit, as in real gait) and both elbows lowered by 25 deg (to 3-43
deg: nearly straight arms in part of the trial, which inverse kinematics of the nominal model
puts in another basin, elbow on its limit and arm turned about its long axis), on every
second frame (54 frames) and on every frame (108 frames), 50 markers. The true model fits
them exactly (checked: markers that no pose of the model reaches, such as a coupled
coordinate set apart from its coupler, are fit better by other parameters than by the truth,
and the case would have no known answer). The nominal model has the right knee's parent
frame moved 35 mm and all four knee frames turned by 3.6-6 deg about x and y; JMP frees
exactly those 11 parameters.
"""

from __future__ import annotations

import warnings

import attrs
import numpy as np
import pytest

from nmsm.cli import main
from nmsm.io.storage import read_storage, write_storage
from nmsm.model import load_model
from nmsm.model.osim_writer import OsimWriter
from nmsm.tools.jmp.ik import inverse_kinematics
from nmsm.tools.jmp.run import run_settings

GAIT = "preprocessing/uf_subject3_tutorial/PreCompleted/input_data/GaitTrial_IKResults.mot"
SHIFT = np.radians(6.0)
#: frame path -> orientation offsets (x, y) in units of SHIFT
TURNS = {("knee_r", "parent"): (-1.0, -0.8), ("knee_r", "child"): (-0.7, -1.0),
         ("knee_l", "parent"): (0.9, 1.0), ("knee_l", "child"): (-1.0, 0.6)}
MOVE = np.array([-0.02, 0.025, -0.015])  # m, |MOVE| = 35 mm
#: coordinate -> how far the motion lowers it, held at its lower limit 0 (deg)
LOWERED = {"knee_angle_r": np.degrees(SHIFT) / 3.0, "knee_angle_l": np.degrees(SHIFT) / 3.0,
           "elbow_flex_r": 25.0, "elbow_flex_l": 25.0}
#: iterations of the joint solve: frames in another basin are re-seated during the solve, not after a crawl
MAX_ITERATIONS = 100

JOINT = """<JMPJoint name="{name}">
<parent_frame_transformation><translation>{translation}</translation><orientation>true true false</orientation>
<translation_bounds>0.05</translation_bounds><orientation_bounds>0.3</orientation_bounds></parent_frame_transformation>
<child_frame_transformation><translation>false false false</translation><orientation>true true false</orientation>
<translation_bounds>0.05</translation_bounds><orientation_bounds>0.3</orientation_bounds></child_frame_transformation>
</JMPJoint>"""


def _settings(markers: list[str]) -> str:
    joints = (JOINT.format(name="knee_r", translation="true true true")
              + JOINT.format(name="knee_l", translation="false false false"))
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.0"><JointModelPersonalizationTool name="knees">
<results_directory>results</results_directory><input_model_file>nominal.osim</input_model_file>
<output_model_file>personalized.osim</output_model_file><allowable_error>0.01</allowable_error>
<JMPTaskList><JMPTask name="knees"><is_enabled>true</is_enabled><index>1</index>
<marker_file_name>markers.trc</marker_file_name><marker_names>{' '.join(markers)}</marker_names>
<JMPJointSet>{joints}</JMPJointSet></JMPTask></JMPTaskList>
</JointModelPersonalizationTool></NMSMPipelineDocument>
"""


@pytest.mark.slow
@pytest.mark.parametrize("step", [2, 1], ids=["54_frames", "108_frames"])
def test_knees_of_full_body_model_are_recovered_exactly(shared_data, tmp_path, step):
    true_model = tmp_path / "true.osim"
    true_model.write_bytes((shared_data / "models/RCNL2024.osim").read_bytes())
    gait = read_storage(shared_data / GAIT)
    data = gait.data.copy()
    for coordinate, lowered in LOWERED.items():
        column = gait.labels.index(coordinate)
        data[:, column] = np.maximum(data[:, column] - lowered, 0.0)
    assert (data[:, gait.labels.index("knee_angle_r")] == 0.0).sum() >= 3
    motion = write_storage(tmp_path / "motion.mot", attrs.evolve(gait, time=gait.time[::step], data=data[::step]),
                           name="Coordinates")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the motion's locked mtp angles (tests/model/test_cli.py)
        markers = tmp_path / "markers.trc"
        assert main(["markers", str(true_model), str(motion), "--units", "mm", "-o", str(markers)]) == 0
        assert inverse_kinematics(true_model, markers).marker_max() <= 1e-6  # m: perfect markers
    model = load_model(true_model)
    writer = OsimWriter(true_model)
    truth = {}
    for (joint, which), (x, y) in TURNS.items():
        path = writer.joint_frame_path(joint, which)
        orientation = model.frames[path].orientation
        truth[f"{joint} {which} orientation x"], truth[f"{joint} {which} orientation y"] = orientation[:2]
        writer.set_frame_orientation(path, orientation + SHIFT * np.array([x, y, 0.0]))
    path = writer.joint_frame_path("knee_r", "parent")
    translation = model.frames[path].translation
    truth.update({f"knee_r parent translation {a}": v for a, v in zip("xyz", translation)})
    writer.set_frame_translation(path, translation + MOVE)
    writer.write(tmp_path / "nominal.osim")
    (tmp_path / "settings.xml").write_text(_settings([m.name for m in model.markers]))

    run = run_settings(tmp_path / "settings.xml", quiet=True)
    task = run.tasks[0]
    found = {v.label: float(x) for v, x in zip(task.design.variables, task.values)}
    assert set(found) == set(truth)
    for label, value in truth.items():
        limit = 1e-4 if "translation" in label else np.radians(0.1)  # 0.1 mm, 0.1 deg
        assert abs(found[label] - value) <= limit, label
    assert task.before.marker_rms() > 5e-3
    assert task.after.marker_rms() <= 1e-4
    assert task.solution.reseated_frames > 0
    assert task.solution.iterations <= MAX_ITERATIONS

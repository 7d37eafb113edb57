"""A motion file's inDegrees header checked against the model; IK time ranges beyond the markers."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from nmsm.examples.synthetic_jmp import leg_model_xml
from nmsm.io.storage import Table, table_from_columns, write_storage
from nmsm.io.trc import MarkerTable, write_trc
from nmsm.model import load_model
from nmsm.tools.jmp.ik import run_ik_files
from nmsm.tools.jmp.marker_model import MarkerKinematics
from nmsm.io.motion_units import implausible_angle_message

GAIT_DEGREES = {"hip_flexion_r": (-10.0, 35.0), "knee_angle_r": (-65.0, -2.0), "pelvis_rotation": (85.0, 95.0)}
RANGES = {"hip_flexion_r": (-0.5, 2.0), "knee_angle_r": (-2.1, 0.17), "pelvis_rotation": (-1.57, 1.57)}


def _motion(in_degrees: bool, scale: float) -> Table:
    t = np.linspace(0.0, 1.0, 101)
    columns = {k: scale * (lo + (hi - lo) * (0.5 + 0.5 * np.sin(2 * np.pi * t)))
               for k, (lo, hi) in GAIT_DEGREES.items()}
    columns["pelvis_tx"] = 1.2 * t  # translation: never converted, never checked
    return table_from_columns(t, columns, in_degrees=in_degrees)


def test_right_headers_are_silent():
    assert implausible_angle_message(_motion(True, 1.0), RANGES) is None
    assert implausible_angle_message(_motion(False, np.pi / 180), RANGES) is None
    assert implausible_angle_message(_motion(False, np.pi / 180), set(RANGES)) is None


def test_degrees_marked_radians():
    message = implausible_angle_message(_motion(False, 1.0), RANGES, file="ik.mot")
    assert message.startswith("ik.mot: read with inDegrees=no, rotational column(s) 'hip_flexion_r' -10..35 rad "
                              "(-573..2005 deg), outside [-2π, 2π] rad")
    assert "'pelvis_rotation' 85..95 rad" in message and "pelvis_tx" not in message
    assert message.endswith("the header may be wrong (inDegrees=yes)")


def test_radians_marked_degrees():
    message = implausible_angle_message(_motion(True, np.pi / 180), RANGES, file="ik.mot")
    assert message.startswith("ik.mot: inDegrees=yes, but every rotational column as written lies within [-π, π]")
    assert "'knee_angle_r', is -1.134..-0.03491 as written, read as -0.0198..-0.0006092 rad (-1.134..-0.03491 deg)" \
        in message
    assert "as radians it would be -1.134..-0.03491 rad (-65..-2 deg)" in message
    assert message.endswith("the header may be wrong (inDegrees=no)")


def test_far_outside_the_models_range():
    t = np.linspace(0.0, 1.0, 11)
    small = table_from_columns(t, {"knee_angle_r": -6.0 + 0 * t})  # -6 deg read as rad: inside ±2π
    assert "far outside the model's range -2.1..0.17 rad" in implausible_angle_message(small, RANGES)
    assert implausible_angle_message(small, set(RANGES)) is None  # no range known: inside ±2π is plausible


@pytest.fixture
def leg(tmp_path):
    path = tmp_path / "leg.osim"
    path.write_bytes(leg_model_xml())
    model = load_model(path)
    kin = MarkerKinematics(model, model.marker_names)
    time = np.linspace(0.0, 1.0, 26)
    q = np.column_stack([0.2 * np.sin(2 * np.pi * time + k) for k in range(kin.n_free)])
    q[:, kin.free_names.index("knee_angle")] = -0.9 + 0.7 * np.sin(2 * np.pi * time)
    q[:, kin.free_names.index("pelvis_ty")] += 0.93
    write_trc(tmp_path / "leg.trc", MarkerTable(time=time, names=tuple(model.marker_names),
                                                positions=kin.marker_positions(q), units="m"), units="m")
    return tmp_path, path, model, kin, q, time


def _ik_settings(folder, time_range: str, task: str = "") -> None:
    coordinates = "<coordinate_file>coords.mot</coordinate_file>" if task else ""
    task += "".join(f'<IKMarkerTask name="{m}"><apply>true</apply><weight>1</weight></IKMarkerTask>'
                    for m in load_model(folder / "leg.osim").marker_names)
    (folder / "ik.xml").write_text(f"""<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000"><InverseKinematicsTool>
  <accuracy>1e-8</accuracy><IKTaskSet><objects>{task}</objects></IKTaskSet>
  <marker_file>leg.trc</marker_file>{coordinates}
  <time_range>{time_range}</time_range>
</InverseKinematicsTool></OpenSimDocument>""")


def test_ik_coordinate_file_with_the_wrong_header_warns(leg):
    folder, path, model, kin, q, time = leg
    knee = q[:, kin.free_names.index("knee_angle")]
    write_storage(folder / "coords.mot", table_from_columns(time, {"knee_angle": np.degrees(knee)}, in_degrees=False))
    _ik_settings(folder, "0 1", '<IKCoordinateTask name="knee_angle"><apply>true</apply><weight>1</weight>'
                                '<value_type>from_file</value_type></IKCoordinateTask>')
    with pytest.warns(UserWarning, match=r"coords.mot: read with inDegrees=no, rotational column\(s\) 'knee_angle' "
                                         r"-91.59..-11.54 rad \(-5248..-661.1 deg\), outside \[-2π, 2π\] rad"):
        run_ik_files(path, ik_settings=folder / "ik.xml")
    write_storage(folder / "coords.mot", table_from_columns(time, {"knee_angle": np.degrees(knee)}, in_degrees=True))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run_ik_files(path, ik_settings=folder / "ik.xml")


def test_ik_settings_time_range_beyond_the_markers_warns(leg):
    folder, path, *_ = leg
    _ik_settings(folder, "0.5 7")
    with pytest.warns(UserWarning, match=r"ik.xml: <time_range> 0.5-7 s reaches beyond the marker data .*leg.trc "
                                         r"\(0-1 s\); using its frames in 0.52-1 s"):
        result = run_ik_files(path, ik_settings=folder / "ik.xml")
    assert result.time[-1] == pytest.approx(1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run_ik_files(path, folder / "leg.trc", time_range=(0.5, float("inf")))  # `nmsm ik --start 0.5`
